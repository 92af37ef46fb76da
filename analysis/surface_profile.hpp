#pragma once
// The upper ice surface z_s(x) as seen from the particles (docs/measurement.md):
// per x-bin the highest undamaged particle, with dips bridged so that an open or damaged
// crevasse does not pull the surface down into itself, then smoothed.
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace crevasse::analysis {

struct SurfaceSettings {
  double bin_width_m = 10.0;  // usually the grid spacing dx
  // Dips narrower than twice this are bridged by the chord between the surface points on
  // either side (the crevasse lips). Only concave dips are touched: a convex or straight
  // surface is left as it is.
  double bridge_half_width_m = 50.0;
  int smoothing_bins = 3;  // centred moving average over this many bins (odd; 1 = none)
  // Particles stand for a volume of this half-size: the material surface lies this far above
  // the top particle centre.
  double particle_half_extent_m = 0.0;
  // Called every few thousand bins of the bridging, whose work grows with the square of the
  // bridge's width in bins; it throws to abandon the profile (MeasurePoll).
  std::function<void()> poll;
};

struct SurfaceProfile {
  double x0_m = 0.0;  // left edge of bin 0
  double bin_width_m = 0.0;
  std::vector<double> z_m;  // surface height at bin centres [m]
  // 1 where the bin held an undamaged particle; 0 where its height was bridged or
  // interpolated from neighbours (no undamaged particle, or a crevasse dip).
  std::vector<std::uint8_t> measured;

  bool empty() const { return z_m.empty(); }
  std::size_t size() const { return z_m.size(); }
  double bin_center_x(std::size_t i) const {
    return x0_m + (static_cast<double>(i) + 0.5) * bin_width_m;
  }
  // z_s(x) by linear interpolation between bin centres, held constant past the ends.
  double height_at(double x_m) const;
};

// x, z: particle positions in the vertical plane; damaged: 1 for a damaged particle.
// Bins with no undamaged particle take the height of any particle in them only when the whole
// set has no undamaged particle at all (a fully fragmented slab), so the profile is defined.
SurfaceProfile compute_surface_profile(std::span<const double> x, std::span<const double> z,
                                       std::span<const std::uint8_t> damaged,
                                       const SurfaceSettings& settings);

}  // namespace crevasse::analysis
