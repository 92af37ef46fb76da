#pragma once
// Combines the databases of one study's shards (or of repeated runs) into one, for
// `crevasse merge` (cli/merge_command.cpp). A case stored in several inputs is kept once; a
// finished case beats a pending one; two finished copies with different results (result_hash)
// are a conflict: the first is kept and the conflict reported.
#include <filesystem>
#include <string>
#include <vector>

namespace crevasse {

struct MergeReport {
  std::size_t inputs = 0;
  std::size_t copied = 0;     // cases added or upgraded (pending → finished)
  std::size_t identical = 0;  // already present with the same result
  std::size_t conflicts = 0;
  std::vector<std::string> conflict_lines;  // one line per conflict
};

// Throws InputError when an input is missing, is OUT itself, or holds another study.
MergeReport merge_databases(const std::filesystem::path& out,
                            const std::vector<std::filesystem::path>& inputs);

}  // namespace crevasse
