#include "engine/volume_average.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "engine/particle_update.hpp"
#include "engine/velocity_gather.hpp"

namespace crevasse {
namespace {
constexpr std::size_t kGrain = 1024;
}  // namespace

template <int Dim>
void VolumeAverage<Dim>::gather_and_scatter(Particles<Dim>& P, const Grid<Dim>& grid,
                                            const ParticleColouring<Dim>& colouring, double dt,
                                            bool damage) {
  const double dx = grid.dx, inv_dx = 1.0 / dx, c_scale = 4.0 * inv_dx * inv_dx;
  nodal_.assign(2 * grid.node_count(),
                0.0);  // per node Σ w m (1−D) ΔJ (and ΔJ J_E), then (ΔJ̄, has one)
  double* const aux = nodal_.data();
  const bool relax = per_cell_ && relaxation_time_ > 0.0;
  nodal_total_.resize(relax ? grid.node_count() : 0);  // written by normalise
  const std::array<std::size_t, Dim> stride = grid.strides();
  colouring.for_each([&](std::uint32_t p) __attribute__((always_inline)) {
    const Vec<Dim> xg = P.x[p] * inv_dx;
    const StencilWeights<Dim> w(xg);
    const std::size_t f0 = grid.flat(w.base());
    gather_velocity(P, grid, p, w, StencilOffsets<Dim>(w, xg, dx), f0, c_scale);
    const double dj = per_cell_ ? step_volume_ratio(P, p, dt) : averaged_volume_ratio(P, p, dt);
    const double wm = weight(P, p, damage);  // the weight P2G added to intact_mass
    if (relax) {
      // The whole volume's sum goes in each node's second slot, free until the normalisation.
      const double jt = dj * P.F_e[p].determinant();
      for_each_stencil_node<Dim>(w, f0, stride, [&](const IVec<Dim>&, std::size_t f, double wt) {
        aux[2 * f] += wt * wm * dj;
        aux[2 * f + 1] += wt * wm * jt;
      });
      return;
    }
    for_each_stencil_node<Dim>(w, f0, stride, [&](const IVec<Dim>&, std::size_t f, double wt) {
      aux[2 * f] += wt * wm * dj;
    });
  });
}

template <int Dim>
void VolumeAverage<Dim>::normalise(const Grid<Dim>& grid) {
  // Nodes reached only by (nearly) broken ice carry no average.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid.node_count(), kGrain),
                    [&](const auto& r) {
                      for (std::size_t f = r.begin(); f != r.end(); ++f) {
                        const double intact = grid.nodes[f].intact_mass;
                        const bool has = intact > 1e-9 * grid.nodes[f].mass;
                        if (!nodal_total_.empty())
                          nodal_total_[f] = has ? nodal_[2 * f + 1] / intact : 0.0;
                        nodal_[2 * f] = has ? nodal_[2 * f] / intact : 0.0;
                        nodal_[2 * f + 1] = has ? 1.0 : 0.0;
                      }
                    });
}

template <int Dim>
void VolumeAverage<Dim>::average_over_cells(const Particles<Dim>& P, const Grid<Dim>& grid,
                                            const ParticleColouring<Dim>& colouring, double dt,
                                            bool damage) {
  // Each particle's trial elastic volume ratio, its own elastic volume times the
  // stencil-averaged step ratio, is averaged over the particles of its grid cell (weights as in
  // the nodal average); the update gives it the cell's mean.
  const double inv_dx = 1.0 / grid.dx;
  cell_.assign(2 * grid.node_count(), 0.0);
  double* const aux = cell_.data();
  colouring.for_each([&](std::uint32_t p) __attribute__((always_inline)) {
    const Vec<Dim> xg = P.x[p] * inv_dx;
    const StencilWeights<Dim> w(xg);
    const Vec<2> sums = stencil_sums(grid, w);
    const double dj = step_volume_ratio(P, p, dt);
    const double share = damage ? softening_[p] : 1.0;
    const double total = volume_scale_of(sums[0], sums[1], dj, share) * dj * P.F_e[p].determinant();
    const double wm = weight(P, p, damage);
    const std::size_t c = grid.flat(cell_of(xg));
    aux[2 * c] += wm * total;
    aux[2 * c + 1] += wm;
  });
  // The nodes' ΔJ̄ has served; with the relaxation, their whole-volume average takes its slot,
  // beside the flag the update needs with it.
  const bool relax = !nodal_total_.empty();
  double* const nodal = nodal_.data();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid.node_count(), kGrain),
                    [&](const auto& r) {
                      for (std::size_t f = r.begin(); f != r.end(); ++f) {
                        const bool has = aux[2 * f + 1] > 0.0;
                        aux[2 * f] = has ? aux[2 * f] / aux[2 * f + 1] : 0.0;
                        aux[2 * f + 1] = has ? 1.0 : 0.0;
                        if (relax) nodal[2 * f] = nodal_total_[f];
                      }
                    });
}

template class VolumeAverage<2>;
template class VolumeAverage<3>;

}  // namespace crevasse
