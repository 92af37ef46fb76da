#pragma once
// Opened gaps inside the ice (docs/measurement.md, "Opened gaps"): once a crack has opened, the
// ice on either side is intact and the crack itself is empty space. These are the cells dx wide
// that hold no particle yet lie wholly below the (bridged) surface and above the bed, in a
// connected patch that borders damaged ice (a crack opens from ice that failed: a dip of the
// surface between intact slopes is not one); each is returned as points on the particle lattice,
// to be counted as damaged material.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "analysis/surface_profile.hpp"

namespace crevasse::analysis {

struct GapPoints {
  std::vector<double> x, z;
  std::size_t cell_count = 0;
};

// `bed` is the bed polyline (x ascending); without one (fewer than two vertices) the lowest
// particle stands for the bed. Cells are aligned with the surface profile's bins.
GapPoints find_opened_gaps(std::span<const double> x, std::span<const double> z,
                           std::span<const std::uint8_t> damaged, const SurfaceProfile& surface,
                           const std::vector<std::array<double, 2>>& bed, double dx_m, double particle_spacing_m);

}  // namespace crevasse::analysis
