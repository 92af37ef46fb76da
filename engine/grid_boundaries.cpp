#include "engine/grid_boundaries.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "engine/bspline.hpp"

namespace crevasse {
namespace {
constexpr std::size_t kGrain = 1024;
}  // namespace

template <int Dim>
void hold_nodes_at_speed(Grid<Dim>& grid, double x_lo, double x_hi, double speed, bool hold_vertical) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid.node_count(), kGrain), [&](const auto& r) {
    for (std::size_t f = r.begin(); f != r.end(); ++f) {
      if (grid.nodes[f].mass <= 0.0) continue;
      const double x = grid.position(grid.node_of(f))[0];
      if (x < x_lo || x > x_hi) continue;
      if (hold_vertical) grid.nodes[f].vel.setZero();
      grid.nodes[f].vel[0] = speed;
    }
  });
}

template <int Dim>
void pull_nodes_with_piston(Grid<Dim>& grid, const Particles<Dim>& P, double speed, std::vector<double>& layer_mass) {
  // v_x ← v_x + f (V − v_x), f = m_layer/m_node. Without it the layer, moved kinematically,
  // overran the ice in front of it (the ice there moved at the grid's mass-averaged speed,
  // ~0.94 vs 1.17 m/s at t = 15 s) and tore a full-depth crack a few cells ahead of the piston.
  // The share varies smoothly as the layer moves, so no node switches on abruptly.
  const double inv_dx = 1.0 / grid.dx;
  layer_mass.assign(grid.node_count(), 0.0);
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (std::isnan(P.drive_x0[p])) continue;
    const StencilWeights<Dim> w(P.x[p] * inv_dx);
    const IVec<Dim> base = w.base();
    for_each_stencil_node<Dim>(w, [&](const IVec<Dim>& off, double wt) {
      layer_mass[grid.flat(base + off)] += wt * P.mass[p];
    });
  }
  for (std::size_t f = 0; f < layer_mass.size(); ++f) {
    if (layer_mass[f] <= 0.0 || grid.nodes[f].mass <= 0.0) continue;
    const double share = std::min(1.0, layer_mass[f] / grid.nodes[f].mass);
    grid.nodes[f].vel[0] += share * (speed - grid.nodes[f].vel[0]);
  }
}

template <int Dim>
void apply_bed_friction(Grid<Dim>& grid, const BedField<Dim>& bed, double mu) {
  // Remove the approaching normal velocity v_n < 0 and reduce the tangential velocity by μ|v_n|
  // (stick if it would reverse). Separating nodes (v_n ≥ 0) are free, so ice may lift off the bed.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid.node_count(), kGrain), [&](const auto& r) {
    for (std::size_t f = r.begin(); f != r.end(); ++f) {
      if (grid.nodes[f].mass <= 0.0) continue;
      Vec<Dim> n;
      // Nodes on the bed surface have φ = 0 up to round-off in the distance computation.
      if (!bed.contact_normal(grid.node_of(f), 1e-6 * grid.dx, n)) continue;
      Vec<Dim>& v = grid.nodes[f].vel;
      const double vn = v.dot(n);
      if (vn >= 0.0) continue;
      Vec<Dim> vt = v - vn * n;
      const double vt_norm = vt.norm();
      if (vt_norm <= -mu * vn) vt.setZero();
      else vt *= 1.0 + mu * vn / vt_norm;
      v = vt;
    }
  });
}

template <int Dim>
void apply_free_slip_walls(Grid<Dim>& grid, const std::vector<int>& axes, const Vec<Dim>& lo, const Vec<Dim>& hi) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid.node_count(), kGrain), [&](const auto& r) {
    for (std::size_t f = r.begin(); f != r.end(); ++f) {
      if (grid.nodes[f].mass <= 0.0) continue;
      const Vec<Dim> xn = grid.position(grid.node_of(f));
      for (int a : axes) {
        if (xn[a] <= lo[a] + 1e-9 * grid.dx) grid.nodes[f].vel[a] = std::max(grid.nodes[f].vel[a], 0.0);
        if (xn[a] >= hi[a] - 1e-9 * grid.dx) grid.nodes[f].vel[a] = std::min(grid.nodes[f].vel[a], 0.0);
      }
    }
  });
}

template <int Dim>
void apply_velocity_boxes(Grid<Dim>& grid, const std::vector<VelocityBox>& boxes, double time) {
  for (const auto& b : boxes) {
    const Vec<Dim> v = to_vec<Dim>(b.velocity);
    const Vec<Dim> lo = to_vec<Dim>(b.min) + v * time, hi = to_vec<Dim>(b.max) + v * time;
    for (std::size_t f = 0; f < grid.node_count(); ++f) {
      if (grid.nodes[f].mass <= 0.0) continue;
      const Vec<Dim> xn = grid.position(grid.node_of(f));
      if ((xn.array() >= lo.array()).all() && (xn.array() <= hi.array()).all()) grid.nodes[f].vel = v;
    }
  }
}

#define CREVASSE_GRID_BOUNDARIES(D)                                                                       \
  template void hold_nodes_at_speed<D>(Grid<D>&, double, double, double, bool);                          \
  template void pull_nodes_with_piston<D>(Grid<D>&, const Particles<D>&, double, std::vector<double>&);  \
  template void apply_bed_friction<D>(Grid<D>&, const BedField<D>&, double);                             \
  template void apply_free_slip_walls<D>(Grid<D>&, const std::vector<int>&, const Vec<D>&, const Vec<D>&); \
  template void apply_velocity_boxes<D>(Grid<D>&, const std::vector<VelocityBox>&, double);
CREVASSE_GRID_BOUNDARIES(2)
CREVASSE_GRID_BOUNDARIES(3)
#undef CREVASSE_GRID_BOUNDARIES

}  // namespace crevasse
