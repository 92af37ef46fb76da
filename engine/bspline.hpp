#pragma once
// Quadratic B-spline weights (C1, support of three nodes per axis), the kernel of MLS-MPM
// (Hu et al. 2018, ACM TOG 37(4) 150). For a particle at grid coordinate xi = x/dx the three
// nodes are base, base+1, base+2 with base = floor(xi − 0.5).
#include <array>
#include <cmath>

#include "engine/types.hpp"

namespace crevasse {

struct QuadraticWeights1d {
  int base = 0;
  std::array<double, 3> w{};
};

inline QuadraticWeights1d quadratic_weights(double xi) {
  QuadraticWeights1d out;
  out.base = static_cast<int>(std::floor(xi - 0.5));
  const double fx = xi - out.base;  // in [0.5, 1.5)
  out.w[0] = 0.5 * (1.5 - fx) * (1.5 - fx);
  out.w[1] = 0.75 - (fx - 1.0) * (fx - 1.0);
  out.w[2] = 0.5 * (fx - 0.5) * (fx - 0.5);
  return out;
}

// Per-axis weights of one particle, and the tensor-product weight of one of its 3^Dim nodes.
template <int Dim>
struct StencilWeights {
  std::array<QuadraticWeights1d, Dim> axis;

  explicit StencilWeights(const Vec<Dim>& x_over_dx) {
    for (int a = 0; a < Dim; ++a) axis[a] = quadratic_weights(x_over_dx[a]);
  }
  IVec<Dim> base() const {
    IVec<Dim> b;
    for (int a = 0; a < Dim; ++a) b[a] = axis[a].base;
    return b;
  }
  // offset: each component in {0,1,2}
  double weight(const IVec<Dim>& offset) const {
    double w = 1.0;
    for (int a = 0; a < Dim; ++a) w *= axis[a].w[offset[a]];
    return w;
  }
};

// Calls f(offset, weight) for the 3^Dim nodes of a stencil.
template <int Dim, class F>
inline void for_each_stencil_node(const StencilWeights<Dim>& s, F&& f) {
  if constexpr (Dim == 2) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) f(IVec<2>(i, j), s.axis[0].w[i] * s.axis[1].w[j]);
  } else {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          f(IVec<3>(i, j, k), s.axis[0].w[i] * s.axis[1].w[j] * s.axis[2].w[k]);
  }
}

}  // namespace crevasse
