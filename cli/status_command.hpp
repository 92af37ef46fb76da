#pragma once
// `crevasse status DB`: what a study database holds, readable while the study runs.
// `crevasse status --compute DB...`: the compute several databases hold, as one Markdown table.
#include <string>
#include <vector>

namespace crevasse {

struct StatusCommandOptions {
  std::vector<std::string> db_paths;
  bool all_cases = false;  // list every case, however many
  bool compute_table = false;  // the compute per database and H_i (study/study_compute.hpp)
};

int status_command(const StatusCommandOptions& opt);

}  // namespace crevasse
