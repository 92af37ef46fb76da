#pragma once
// `--shard I/N`: a deterministic share of a study's cases for one machine or SLURM array task.
// The cases are ordered by their hash and case k of that order goes to shard k mod N, so the
// split depends only on which cases the study holds (not on key order in the file), every
// case is in exactly one shard, and shard sizes differ by at most one.
#include <string>
#include <vector>

#include "study/study_file.hpp"

namespace crevasse {

struct Shard {
  int index = 0;  // I, in [0, count)
  int count = 1;  // N ≥ 1
  std::string text() const { return std::to_string(index) + "/" + std::to_string(count); }
};

// Parses "I/N" with 0 ≤ I < N; throws InputError naming --shard otherwise.
Shard parse_shard(const std::string& text);

// The cases of `study` in shard `shard`, in enumeration order.
std::vector<const StudyCase*> shard_cases(const Study& study, const Shard& shard);

// `--cases LIST`: case indices as `--dry-run` lists them, comma-separated, a-b for a range
// (e.g. "30,33" or "20-25,38"); sorted, without repeats. Throws InputError naming --cases and
// the allowed range [0, case_count - 1] otherwise.
std::vector<std::size_t> parse_case_list(const std::string& text, std::size_t case_count);

}  // namespace crevasse
