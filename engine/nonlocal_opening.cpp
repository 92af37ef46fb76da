#include "engine/nonlocal_opening.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "engine/bspline.hpp"

namespace crevasse {

template <int Dim>
NonlocalOpening<Dim>::NonlocalOpening(double radius, double weight, double dx) : radius_(radius), weight_(weight) {
  if (!(radius_ > 0.0)) return;
  const int k = static_cast<int>(std::floor(radius_ / dx));
  IVec<Dim> o = IVec<Dim>::Constant(-k);
  for (;;) {
    const double r2 = o.template cast<double>().squaredNorm() * dx * dx;
    if (r2 < radius_ * radius_) {
      const double s = 1.0 - r2 / (radius_ * radius_);
      offsets_.push_back({o, s * s});
    }
    int a = 0;
    while (a < Dim && ++o[a] > k) o[a++] = -k;
    if (a == Dim) break;
  }
}

template <int Dim>
void NonlocalOpening<Dim>::compute(const Particles<Dim>& P, const Grid<Dim>& grid,
                                   const ParticleColouring<Dim>& colouring) {
  const std::size_t nodes = grid.node_count();
  nodal_.assign(2 * nodes, 0.0);
  averaged_.assign(nodes, 0.0);
  eps_hat_.resize(P.size());
  const double inv_dx = 1.0 / grid.dx;
  const auto stride = grid.strides();
  double* const sums = nodal_.data();
  colouring.for_each([&](std::uint32_t p) {
    const StencilWeights<Dim> w(P.x[p] * inv_dx);
    const double m = P.mass[p], me = m * P.eps_v_p[p];
    for_each_stencil_node<Dim>(w, grid.flat(w.base()), stride, [&](const IVec<Dim>&, std::size_t f, double wt) {
      sums[2 * f] += wt * me;
      sums[2 * f + 1] += wt * m;
    });
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nodes, 256), [&](const auto& r) {
    for (std::size_t f = r.begin(); f != r.end(); ++f) {
      if (!(nodal_[2 * f + 1] > 0.0)) continue;
      const IVec<Dim> node = grid.node_of(f);
      double num = 0.0, den = 0.0;
      for (const Offset& o : offsets_) {
        const IVec<Dim> q = node + o.node;
        bool inside = true;
        for (int a = 0; a < Dim; ++a) inside = inside && q[a] >= grid.lo[a] && q[a] < grid.lo[a] + grid.n[a];
        if (!inside) continue;
        const std::size_t g = grid.flat(q);
        num += o.weight * nodal_[2 * g];
        den += o.weight * nodal_[2 * g + 1];
      }
      averaged_[f] = num / den;  // den ≥ the node's own mass > 0
    }
  });
  const double m = weight_;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, P.size(), 1024), [&](const auto& r) {
    for (std::size_t p = r.begin(); p != r.end(); ++p) {
      const StencilWeights<Dim> w(P.x[p] * inv_dx);
      double bar = 0.0;
      for_each_stencil_node<Dim>(w, grid.flat(w.base()), stride,
                                 [&](const IVec<Dim>&, std::size_t f, double wt) { bar += wt * averaged_[f]; });
      // Over-nonlocal (m > 1) can dip below zero next to a band; an opening is never negative.
      eps_hat_[p] = std::max(0.0, m * bar + (1.0 - m) * P.eps_v_p[p]);
    }
  });
}

template class NonlocalOpening<2>;
template class NonlocalOpening<3>;

}  // namespace crevasse
