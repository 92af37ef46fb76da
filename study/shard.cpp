#include "study/shard.hpp"

#include <algorithm>
#include <charconv>

#include "engine/error.hpp"

namespace crevasse {

Shard parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  auto parse_int = [&](const std::string& s, int& out) {
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && ptr == s.data() + s.size() && !s.empty();
  };
  Shard sh;
  if (slash == std::string::npos || !parse_int(text.substr(0, slash), sh.index) ||
      !parse_int(text.substr(slash + 1), sh.count))
    throw InputError("--shard: '" + text +
                     "' is not of the form I/N (e.g. 0/4 for the first of 4 shards)");
  if (sh.count < 1 || sh.count > 100000)
    throw InputError("--shard: N = " + std::to_string(sh.count) +
                     " is outside the allowed range [1, 100000]");
  if (sh.index < 0 || sh.index >= sh.count)
    throw InputError("--shard: I = " + std::to_string(sh.index) +
                     " is outside the allowed range [0, " + std::to_string(sh.count - 1) +
                     "] for N = " + std::to_string(sh.count));
  return sh;
}

std::vector<const StudyCase*> shard_cases(const Study& study, const Shard& shard) {
  std::vector<const StudyCase*> by_hash;
  for (const auto& c : study.cases) by_hash.push_back(&c);
  std::sort(by_hash.begin(), by_hash.end(),
            [](const StudyCase* a, const StudyCase* b) { return a->case_id < b->case_id; });
  std::vector<const StudyCase*> out;
  for (std::size_t k = 0; k < by_hash.size(); ++k)
    if (static_cast<int>(k % static_cast<std::size_t>(shard.count)) == shard.index)
      out.push_back(by_hash[k]);
  std::sort(out.begin(), out.end(),
            [](const StudyCase* a, const StudyCase* b) { return a->index < b->index; });
  return out;
}

}  // namespace crevasse
