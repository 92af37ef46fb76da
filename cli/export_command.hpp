#pragma once
// `crevasse export DB --csv DIR`: one CSV file per table. cases.csv flattens each case's
// resolved scene into one column per parameter ("scene.ice.thickness") and its sweep
// coordinates into "axis.<name>" columns.
#include <filesystem>
#include <string>
#include <vector>

namespace crevasse {

struct ExportCommandOptions {
  std::string db_path;
  std::string csv_dir;
};

// Returns the files written.
std::vector<std::filesystem::path> export_csv(const std::filesystem::path& db,
                                              const std::filesystem::path& dir);

int export_command(const ExportCommandOptions& opt);

}  // namespace crevasse
