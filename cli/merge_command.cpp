#include "cli/merge_command.hpp"

#include <cstdio>
#include <filesystem>

#include "study/merge.hpp"
#include "study/store.hpp"

namespace crevasse {

int merge_command(const std::string& out, const std::vector<std::string>& inputs) {
  std::vector<std::filesystem::path> in(inputs.begin(), inputs.end());
  const MergeReport r = merge_databases(out, in);
  for (const auto& line : r.conflict_lines) std::fprintf(stderr, "conflict: %s\n", line.c_str());
  Store store = Store::open_reader(out);
  const StatusCounts c = store.counts();
  std::printf(
      "merged %zu database(s) into %s: %zu case(s) copied, %zu identical, %zu conflict(s); now "
      "%lld done, "
      "%lld failed, %lld pending of %lld\n",
      r.inputs, out.c_str(), r.copied, r.identical, r.conflicts, static_cast<long long>(c.done),
      static_cast<long long>(c.failed), static_cast<long long>(c.pending + c.running),
      static_cast<long long>(c.total()));
  return r.conflicts > 0 ? 1 : 0;
}

}  // namespace crevasse
