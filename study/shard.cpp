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

std::vector<std::size_t> parse_case_list(const std::string& text, std::size_t case_count) {
  const std::string allowed =
      case_count == 0 ? "(the study has no cases)" : "[0, " + std::to_string(case_count - 1) + "]";
  auto parse_index = [&](const std::string& s) {
    std::size_t v = 0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || ptr != s.data() + s.size())
      throw InputError("--cases: '" + text + "' is not a list of case indices (e.g. 30,33 or 20-25)");
    if (v >= case_count)
      throw InputError("--cases: index " + s + " is outside the allowed range " + allowed);
    return v;
  };
  std::vector<std::size_t> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    const std::size_t dash = item.find('-');
    const std::size_t lo = parse_index(item.substr(0, dash));
    const std::size_t hi = dash == std::string::npos ? lo : parse_index(item.substr(dash + 1));
    if (hi < lo)
      throw InputError("--cases: the range " + item + " runs backwards (write " +
                       std::to_string(hi) + "-" + std::to_string(lo) + ")");
    for (std::size_t i = lo; i <= hi; ++i) out.push_back(i);
    start = comma + 1;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
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
