#pragma once
// Connected regions of damaged particles in the vertical (x, z) plane: two damaged particles
// belong to the same region when a chain of damaged particles links them with steps no longer
// than the link distance. Union-find over a cell hash, O(N log N) in the damaged count.
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace crevasse::analysis {

struct DamageClusters {
  static constexpr std::int32_t kNone = -1;
  std::vector<std::int32_t> label;  // per particle: cluster index, or kNone if not damaged
  std::size_t count = 0;            // clusters are numbered 0 .. count-1
};

// `poll` is called every thousand cells and may throw to abandon the search (MeasurePoll).
DamageClusters find_damage_clusters(std::span<const double> x, std::span<const double> z,
                                    std::span<const std::uint8_t> damaged, double link_distance_m,
                                    const std::function<void()>& poll = {});

}  // namespace crevasse::analysis
