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

}  // namespace crevasse
