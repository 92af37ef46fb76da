#pragma once
// `crevasse merge OUT.db IN1.db IN2.db ...`: merge_databases (study/merge.hpp), then the report.
#include <string>
#include <vector>

namespace crevasse {

// Prints the report; returns 0, or 1 when there were conflicts.
int merge_command(const std::string& out, const std::vector<std::string>& inputs);

}  // namespace crevasse
