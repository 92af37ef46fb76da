#pragma once
// The first half of G2P for one particle: its velocity and affine matrix from the grid.
#include "engine/bspline.hpp"
#include "engine/grid.hpp"
#include "engine/particles.hpp"

namespace crevasse {

// APIC/MLS gather of particle p's velocity and its affine matrix C = c_scale·B (c_scale =
// 4/dx², formed once by the caller) from the grid's node velocities (gather_apic); f0 = flat
// index of the stencil's base node. Reads the nodes' velocity; writes v and C of p.
template <int Dim>
[[gnu::always_inline]] inline void gather_velocity(Particles<Dim>& P, const Grid<Dim>& grid,
                                                   std::size_t p, const StencilWeights<Dim>& w,
                                                   const StencilOffsets<Dim>& d, std::size_t f0,
                                                   double c_scale) {
  const GridNode<Dim>* const nodes = grid.nodes.data();
  Vec<Dim> v;
  Mat<Dim> b;
  gather_apic<Dim>(
      w, d, f0, grid.strides(), [nodes](std::size_t f) -> const Vec<Dim>& { return nodes[f].vel; },
      v, b);
  P.v[p] = v;
  P.C[p] = c_scale * b;
}

}  // namespace crevasse
