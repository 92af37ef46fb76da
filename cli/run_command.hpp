#pragma once
// `crevasse run SCENE.json --out DIR`: one simulation, its snapshots, figure and measurements.
#include <string>

namespace crevasse {

struct RunCommandOptions {
  std::string scene_path;
  std::string out_dir;
  double vtu_interval = -1.0;  // overrides output.vtu_interval when ≥ 0
  double measure_interval = 0.0;  // > 0: measure every this many simulated seconds as well
  int threads = 0;             // 0 = all cores
  bool quiet = false;
};

// Returns the process exit code; throws InputError / SimulationError for the CLI to report.
int run_command(const RunCommandOptions& opt);

}  // namespace crevasse
