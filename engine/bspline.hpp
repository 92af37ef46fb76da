#pragma once
// Quadratic B-spline weights (C1, support of three nodes per axis), the kernel of MLS-MPM
// (Hu et al. 2018, ACM TOG 37(4) 150). For a particle at grid coordinate xi = x/dx the three
// nodes are base, base+1, base+2 with base = floor(xi − 0.5).
#include <array>
#include <cstddef>
#include <cmath>

#include "engine/fast_math.hpp"
#include "engine/types.hpp"

namespace crevasse {

struct QuadraticWeights1d {
  int base = 0;
  std::array<double, 3> w{};
};

// Writes the three weights of xi into w and returns the base node.
inline int quadratic_weights_into(double xi, double* w) {
  const int base = floor_to_int(xi - 0.5);
  const double fx = xi - base;  // in [0.5, 1.5)
  w[0] = 0.5 * (1.5 - fx) * (1.5 - fx);
  w[1] = 0.75 - (fx - 1.0) * (fx - 1.0);
  w[2] = 0.5 * (fx - 0.5) * (fx - 0.5);
  return base;
}

inline QuadraticWeights1d quadratic_weights(double xi) {
  QuadraticWeights1d out;
  out.base = quadratic_weights_into(xi, out.w.data());
  return out;
}

// Per-axis weights of one particle, and the tensor-product weight of one of its 3^Dim nodes.
// Plain arrays filled in place: a struct of structs built from returned temporaries went
// through the stack and stalled on store-to-load forwarding in every sweep (docs/performance.md).
template <int Dim>
struct StencilWeights {
  int b[Dim];
  double w[Dim][3];

  explicit StencilWeights(const Vec<Dim>& x_over_dx) {
    for (int a = 0; a < Dim; ++a) b[a] = quadratic_weights_into(x_over_dx[a], w[a]);
  }
  IVec<Dim> base() const {
    IVec<Dim> out;
    for (int a = 0; a < Dim; ++a) out[a] = b[a];
    return out;
  }
  // offset: each component in {0,1,2}
  double weight(const IVec<Dim>& offset) const {
    double wt = 1.0;
    for (int a = 0; a < Dim; ++a) wt *= w[a][offset[a]];
    return wt;
  }
};

// Calls f(offset, weight) for the 3^Dim nodes of a stencil.
template <int Dim, class F>
inline void for_each_stencil_node(const StencilWeights<Dim>& s, F&& f) {
  if constexpr (Dim == 2) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) f(IVec<2>(i, j), s.w[0][i] * s.w[1][j]);
  } else {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          f(IVec<3>(i, j, k), s.w[0][i] * s.w[1][j] * s.w[2][k]);
  }
}

// The same, with each node's flat grid index: f0 is the base node's, stride the grid's flat
// strides (Grid::strides). Calls f(offset, flat index, weight), in the order above. The callers
// hoist what depends on one axis only (the node's distance along it), out of the 3^Dim nodes.
template <int Dim, class F>
inline void for_each_stencil_node(const StencilWeights<Dim>& s, std::size_t f0,
                                  const std::array<std::size_t, Dim>& stride, F&& f) {
  if constexpr (Dim == 2) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        f(IVec<2>(i, j), f0 + static_cast<std::size_t>(i) * stride[0] + static_cast<std::size_t>(j),
          s.w[0][i] * s.w[1][j]);
  } else {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          f(IVec<3>(i, j, k),
            f0 + static_cast<std::size_t>(i) * stride[0] + static_cast<std::size_t>(j) * stride[1] +
                static_cast<std::size_t>(k),
            s.w[0][i] * s.w[1][j] * s.w[2][k]);
  }
}

// Each stencil node's distance from the particle along each axis, (base_a + i − xg_a)·dx, as
// the per-node form (node − xg)·dx computes it: the same doubles, once per axis and node column.
template <int Dim>
struct StencilOffsets {
  double d[Dim][3];
  StencilOffsets(const StencilWeights<Dim>& s, const Vec<Dim>& xg, double dx) {
    for (int a = 0; a < Dim; ++a)
      for (int i = 0; i < 3; ++i) d[a][i] = (static_cast<double>(s.b[a] + i) - xg[a]) * dx;
  }
};

// A small matrix–vector product A·Δx from its column products t_a = A.col(a)·Δx_a, summed in
// the order in which Eigen's fixed-size product sums them in the project's build (SSE2, no
// FMA), so the result is the same double: t0 + t1 in 2D; in 3D (t0 + t1) + t2 for the first two
// rows (one SSE2 packet) and t0 + (t1 + t2) for the third. P2G forms the products once per axis
// and node column and sums them per node (simulation.cpp); tests/engine/test_bspline.cpp checks
// the order against Eigen's product.
inline Vec<2> product_from_columns(const Vec<2>& t0, const Vec<2>& t1) { return t0 + t1; }
inline Vec<3> product_from_columns(const Vec<3>& t0, const Vec<3>& t1, const Vec<3>& t2) {
  return Vec<3>((t0[0] + t1[0]) + t2[0], (t0[1] + t1[1]) + t2[1], t0[2] + (t1[2] + t2[2]));
}

}  // namespace crevasse
