#pragma once
// Cracks that hang from a damaged skin. Stretched ice can lose the strength of its top layer
// along a whole row of cracks; the damaged particles then form one cluster that meets the
// surface all along the row, although a glaciologist sees one crevasse per crack. Below the
// skin the cracks stand apart: in surface bins one particle spacing wide, the cluster reaches
// at least the depth floor under each crack and stays shallower between them.
#include <span>
#include <utility>
#include <vector>

#include "analysis/damage_clusters.hpp"
#include "analysis/surface_profile.hpp"

namespace crevasse::analysis {

// Per cluster, the x-ranges [from, to] of the runs of bins (width `bin_m`, from `x0_m`) in which
// the cluster reaches at least `min_depth_m` below `surface`; a bin with no particle of the
// cluster, or only shallower ones, ends a run. A cluster with fewer than two runs gets none: it
// is one crevasse as it stands.
std::vector<std::vector<std::pair<double, double>>> cracks_under_skin(
    std::span<const double> x, std::span<const double> z, const DamageClusters& clusters,
    const SurfaceProfile& surface, double x0_m, double bin_m, double min_depth_m);

}  // namespace crevasse::analysis
