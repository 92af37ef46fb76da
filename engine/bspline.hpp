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

// A·Δx for every node of a stencil (P2G's affine momentum term), from the column products
// t_a,i = A.col(a)·Δx_a,i formed once per axis and node column (3·Dim products instead of one
// matrix–vector product per node), summed per node in the order in which Eigen's fixed-size
// product A * Δx sums them in the project's build (SSE2, no FMA), so each node gets the same
// double: t0 + t1 in 2D; in 3D (t0 + t1) + t2 for the first two rows (one SSE2 packet) and
// t0 + (t1 + t2) for the third. tests/engine/test_bspline.cpp compares it with A * Δx.
template <int Dim>
struct AffineTerms {
  Vec<Dim> t[Dim][3];
  AffineTerms(const Mat<Dim>& a, const StencilOffsets<Dim>& d) {
    for (int ax = 0; ax < Dim; ++ax)
      for (int i = 0; i < 3; ++i) t[ax][i] = a.col(ax) * d.d[ax][i];
  }
  Vec<Dim> at(const IVec<Dim>& off) const {
    const Vec<Dim>&t0 = t[0][off[0]], &t1 = t[1][off[1]];
    if constexpr (Dim == 2) {
      return t0 + t1;
    } else {
      const Vec<3>& t2 = t[2][off[2]];
      return Vec<3>((t0[0] + t1[0]) + t2[0], (t0[1] + t1[1]) + t2[1], t0[2] + (t1[2] + t2[2]));
    }
  }
};

// The APIC/MLS gather of one particle: v = Σ w v_i and B = Σ w v_i Δxᵀ over its stencil (C is
// 4/dx² B for quadratic B-splines), node velocities from vel(flat index). The products and sums
// per component are v_a += w·v_i,a and B_ab += (w·v_i,a)·Δx_b in node order. In 2D on (x, y)
// pairs, one vector register each for v and the columns of B (g++ 12 leaves the scalar form
// scalar); in 3D in scalar accumulators (Eigen's outer product of 3-vectors goes through stack
// temporaries and stalls on store-to-load forwarding: docs/performance.md).
template <int Dim, class Vel>
inline void gather_apic(const StencilWeights<Dim>& w, const StencilOffsets<Dim>& d, std::size_t f0,
                        const std::array<std::size_t, Dim>& stride, Vel&& vel, Vec<Dim>& v_out,
                        Mat<Dim>& b_out) {
  if constexpr (Dim == 2) {
    Vec<2> v = Vec<2>::Zero(), b0 = Vec<2>::Zero(), b1 = Vec<2>::Zero();
    for_each_stencil_node<2>(w, f0, stride, [&](const IVec<2>& off, std::size_t f, double wt) {
      const Vec<2> wv = wt * vel(f);
      v += wv;
      b0 += wv * d.d[0][off[0]];
      b1 += wv * d.d[1][off[1]];
    });
    v_out = v;
    b_out.col(0) = b0;
    b_out.col(1) = b1;
  } else {
    double v[Dim] = {};
    double b[Dim][Dim] = {};
    for_each_stencil_node<Dim>(w, f0, stride, [&](const IVec<Dim>& off, std::size_t f, double wt) {
      const auto& vi = vel(f);
      for (int a = 0; a < Dim; ++a) {
        const double wv = wt * vi[a];
        v[a] += wv;
        for (int k = 0; k < Dim; ++k) b[a][k] += wv * d.d[k][off[k]];
      }
    });
    for (int a = 0; a < Dim; ++a) {
      v_out[a] = v[a];
      for (int k = 0; k < Dim; ++k) b_out(a, k) = b[a][k];
    }
  }
}

}  // namespace crevasse
