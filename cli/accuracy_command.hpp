#pragma once
// `crevasse accuracy DB --out DIR`: accuracy against cost of a study that varies the numerics
// (studies/accuracy_flowing.json, docs/study_format.md): per case the grid spacing, particles per cell,
// CFL number, drive speed V_x, steps, particle-steps, wall time and peak memory, the median spacing and depth
// and their change against a reference case (by default the finest: the most particle-steps
// among the cases with a spacing). Writes accuracy_cost.csv, accuracy_cost.md (the table) and
// accuracy_cost.png/.svg (median L_p/H_i with quartile bars against wall time, one marker per
// grid spacing (and drive speed, where it differs from the reference's); cases without a
// spacing on the bottom edge). `--add-cases DB` adds the finished cases of other databases as
// rows labelled `<stem>:<index>` (studies/cliff/accuracy_drive.json: the same case at faster drives).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace crevasse {

struct AccuracyCommandOptions {
  std::string db_path;
  std::vector<std::string> add_dbs;  // --add-cases: more rows (e.g. other drive speeds)
  std::string out_dir;
  std::optional<long long> reference_index;  // case_index of the reference case
};

// Returns the files written; `table`, when given, receives the Markdown table.
std::vector<std::filesystem::path> accuracy_report(const AccuracyCommandOptions& opt,
                                                   std::string* table = nullptr);
int accuracy_command(const AccuracyCommandOptions& opt);

}  // namespace crevasse
