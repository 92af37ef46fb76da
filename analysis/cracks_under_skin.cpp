#include "analysis/cracks_under_skin.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace crevasse::analysis {

std::vector<std::vector<std::pair<double, double>>> cracks_under_skin(
    std::span<const double> x, std::span<const double> z, const DamageClusters& clusters,
    const SurfaceProfile& surface, double x0_m, double bin_m, double min_depth_m) {
  std::vector<std::vector<std::pair<double, double>>> out(clusters.count);
  // (cluster, bin, depth below the surface) of every damaged particle.
  std::vector<std::tuple<std::int32_t, long, double>> depth;
  for (std::size_t p = 0; p < x.size(); ++p) {
    const std::int32_t c = clusters.label[p];
    if (c == DamageClusters::kNone) continue;
    depth.emplace_back(c, static_cast<long>(std::floor((x[p] - x0_m) / bin_m)),
                       surface.height_at(x[p]) - z[p]);
  }
  std::sort(depth.begin(), depth.end());
  std::size_t i = 0;
  while (i < depth.size()) {
    const std::int32_t c = std::get<0>(depth[i]);
    std::vector<std::pair<double, double>> runs;
    long run_end = 0;  // last deep bin of the open run
    bool open = false;
    while (i < depth.size() && std::get<0>(depth[i]) == c) {
      const long bin = std::get<1>(depth[i]);
      double deepest = 0.0;
      for (; i < depth.size() && std::get<0>(depth[i]) == c && std::get<1>(depth[i]) == bin; ++i)
        deepest = std::max(deepest, std::get<2>(depth[i]));
      if (deepest < min_depth_m) {
        open = false;
        continue;
      }
      const double from = x0_m + static_cast<double>(bin) * bin_m;
      if (open && bin == run_end + 1)
        runs.back().second = from + bin_m;
      else
        runs.emplace_back(from, from + bin_m);
      open = true;
      run_end = bin;
    }
    if (runs.size() >= 2) out[static_cast<std::size_t>(c)] = std::move(runs);
  }
  return out;
}

}  // namespace crevasse::analysis
