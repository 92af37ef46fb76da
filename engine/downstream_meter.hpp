#pragma once
// The vertical impulse that whatever ends the domain downstream (held nodes, walls, velocity
// boxes) gives the ice: nothing downstream may carry the glacier (docs/model.md). The boundary
// stages between before() and after() are the only ones that can act on the downstream band
// (bed friction and gravity come before); their change of its vertical momentum is the
// impulse. The band is a contiguous tail of the nodes (x is the slowest axis), a few columns:
// negligible next to the step.
#include <algorithm>
#include <cmath>

#include "engine/grid.hpp"

namespace crevasse {

template <int Dim>
class DownstreamImpulseMeter {
 public:
  DownstreamImpulseMeter() = default;
  explicit DownstreamImpulseMeter(double band_x0) : band_x0_(band_x0) {}

  // Reads the nodes' mass and velocity.
  void before(const Grid<Dim>& grid) { before_z_ = band_momentum_z(grid); }
  void after(const Grid<Dim>& grid) { impulse_z_ += band_momentum_z(grid) - before_z_; }
  double impulse_z() const { return impulse_z_; }  // [N·s per unit width in 2D]

 private:
  double band_momentum_z(const Grid<Dim>& grid) const {
    const long first_column = static_cast<long>(std::ceil(band_x0_ / grid.dx)) - grid.lo[0];
    if (first_column >= grid.n[0]) return 0.0;
    double pz = 0.0;
    for (std::size_t f = static_cast<std::size_t>(std::max(0L, first_column)) * grid.stride[0];
         f < grid.nodes.size(); ++f)
      pz += grid.nodes[f].mass * grid.nodes[f].vel[up_axis<Dim>];
    return pz;
  }

  double band_x0_ = 0.0;  // where the band begins along x [m]
  double before_z_ = 0.0;
  double impulse_z_ = 0.0;
};

}  // namespace crevasse
