#pragma once
// `crevasse status DB`: what a study database holds, readable while the study runs.
#include <string>

namespace crevasse {

struct StatusCommandOptions {
  std::string db_path;
  bool all_cases = false;  // list every case, however many
};

int status_command(const StatusCommandOptions& opt);

}  // namespace crevasse
