#pragma once
// ΔJ-bar (cf. the F-bar family, e.g. Coombs et al. 2018, CMAME 333:1–21): the step's volume
// ratio ΔJ_p = det(I + Δt C_p) is mass-averaged onto the grid nodes with the same quadratic
// weights as P2G and interpolated back; each particle then takes the averaged ΔJ̄_p and keeps
// its own isochoric part. A field that varies linearly over the stencil is reproduced, so a
// smooth deformation is unchanged; a particle-to-particle checkerboard is removed.
// Only intact ice is averaged: each particle enters with weight (1 − D) (D the damage,
// 1 − e^{−ζ ε_v^p}) and takes ΔJ_used = (1 − D)·ΔJ̄ + D·ΔJ_p. An opening crack then keeps its
// volume change to itself instead of handing part of it to the intact ice around it, which
// would widen every crack by a cell each time it opens further.
// Three passes, fused with G2P: (1) one coloured sweep gathers v and C and scatters
// (1 − D) m ΔJ and (1 − D) m with the same weights; (2) per node, the average; (3) the update
// sweep interpolates ΔJ̄ back, recomputing ΔJ_p from C (unchanged since (1)). The softening
// factor e^{−ζ ε_v^p} (= 1 − D) is kept per particle from P2G to (3), where the return mapping
// uses it for its cap check and shear strength: a particle that stays off the cap evaluates one
// exponential per step instead of three, and none while intact (e^{−ζ·0} = 1 is not evaluated).
#include <cmath>
#include <cstddef>
#include <vector>

#include "engine/bspline.hpp"
#include "engine/grid.hpp"
#include "engine/particle_colouring.hpp"
#include "engine/particles.hpp"
#include "engine/scene.hpp"

namespace crevasse {

template <int Dim>
class VolumeAverage {
 public:
  // What particle p's update interpolates: the stencil's Σ w ΔJ̄ and Σ w (or with
  // numerics.average_per_cell the cell's mean and whether it has one), and its own ΔJ_p.
  struct Sums {
    double jbar, wsum, dj;
  };

  VolumeAverage() = default;
  explicit VolumeAverage(const SceneConfig& scene)
      : total_volume_(scene.average_total_volume),
        per_cell_(scene.average_per_cell),
        relaxation_time_(scene.average_relaxation_time) {}
  bool per_cell() const { return per_cell_; }

  // P2G: the softening factors kept for the sweeps after (plastic scenes), and each particle's
  // weight, m (1 − D) when the average weights damage (then the kept factor is 1 − D), m
  // otherwise; P2G adds it to the nodes' intact_mass.
  void keep_softening_of(std::size_t particles) { softening_.resize(particles); }
  void keep_softening(std::size_t p, double f) { softening_[p] = f; }
  bool kept_softening() const { return !softening_.empty(); }
  double softening(std::size_t p) const { return softening_[p]; }
  double weight(const Particles<Dim>& P, std::size_t p, bool damage) const {
    return P.mass[p] * (damage ? softening_[p] : 1.0);
  }

  // (1) Gathers v and C (velocity_gather.hpp) and scatters the weighted ΔJ in one coloured
  // sweep. Reads the nodes' velocity, x, C, F_E, mass, the kept softening; writes v, C and the
  // nodal sums.
  void gather_and_scatter(Particles<Dim>& P, const Grid<Dim>& grid,
                          const ParticleColouring<Dim>& colouring, double dt, bool damage);
  // (2) Per node, the averaged ΔJ and whether the node carries one. Reads the nodal sums and the
  // nodes' intact_mass and mass; writes the nodal averages (and whole-volume averages).
  void normalise(const Grid<Dim>& grid);
  // numerics.average_per_cell, after normalise: per cell the mean trial elastic volume. Reads
  // the nodal averages, x, C, F_E, mass, the kept softening; writes the cell means. With the
  // relaxation it then puts the nodes' whole-volume average in the nodal averages' place, where
  // sums() interpolates its target.
  void average_over_cells(const Particles<Dim>& P, const Grid<Dim>& grid,
                          const ParticleColouring<Dim>& colouring, double dt, bool damage);
  // (3) For particle p's update (before it moves). Reads x, C, F_E and the averages.
  [[gnu::always_inline]] inline Sums sums(const Particles<Dim>& P, const Grid<Dim>& grid,
                                          std::size_t p, const StencilWeights<Dim>& w,
                                          double dt) const;

 private:
  double step_volume_ratio(const Particles<Dim>& P, std::size_t p,
                           double dt) const {  // ΔJ = det(I + Δt C)
    return (Mat<Dim>::Identity() + dt * P.C[p]).determinant();
  }
  // What particle p's volume is averaged as: ΔJ, or with numerics.average_total_volume its whole
  // trial elastic volume ratio ΔJ·det F_E. The update scales ΔF by (averaged / this)^{1/d}.
  // (With numerics.average_per_cell the stencil average takes ΔJ and the cell average the rest.)
  double averaged_volume_ratio(const Particles<Dim>& P, std::size_t p, double dt) const {
    const double dj = step_volume_ratio(P, p, dt);
    return total_volume_ ? dj * P.F_e[p].determinant() : dj;
  }
  // (Σ w·first, Σ w·flag) over the stencil from nodal_'s pairs.
  [[gnu::always_inline]] inline Vec<2> stencil_sums(const Grid<Dim>& grid,
                                                    const StencilWeights<Dim>& w) const;
  // The grid cell holding grid coordinate xg (its lower corner node).
  static IVec<Dim> cell_of(const Vec<Dim>& xg) {
    IVec<Dim> c;
    for (int a = 0; a < Dim; ++a) c[a] = static_cast<int>(std::floor(xg[a]));
    return c;
  }

  bool total_volume_ = false;
  bool per_cell_ = false;
  double relaxation_time_ = 0.0;
  // Scratch, reused every step: per node (Σ w m (1−D) ΔJ, unused or with the relaxed per-cell
  // average Σ w m (1−D) ΔJ J_E), then (averaged ΔJ, whether the node carries one); the weights
  // Σ w m (1−D) are in the grid nodes.
  std::vector<double> nodal_;
  std::vector<double> nodal_total_;  // average_relaxation_time: per node the stencil's whole volume
  std::vector<double> cell_;  // average_per_cell: per cell (by its corner node) the mean, has one
  std::vector<double>
      softening_;  // per particle e^{−ζ ε_v^p} (plastic scenes), from P2G to the update
};

template <int Dim>
[[gnu::always_inline]] inline Vec<2> VolumeAverage<Dim>::stencil_sums(
    const Grid<Dim>& grid, const StencilWeights<Dim>& w) const {
  // Each node's two slots are adjacent: one vector load per node.
  const double* const aux = nodal_.data();
  Vec<2> sums = Vec<2>::Zero();
  for_each_stencil_node<Dim>(w, grid.flat(w.base()), grid.strides(),
                             [&](const IVec<Dim>&, std::size_t f, double wt) {
                               sums += wt * Eigen::Map<const Vec<2>>(aux + 2 * f);
                             });
  return sums;
}

template <int Dim>
[[gnu::always_inline]] inline typename VolumeAverage<Dim>::Sums VolumeAverage<Dim>::sums(
    const Particles<Dim>& P, const Grid<Dim>& grid, std::size_t p, const StencilWeights<Dim>& w,
    double dt) const {
  Sums v{0.0, 0.0, 0.0};
  v.dj = averaged_volume_ratio(P, p, dt);
  if (per_cell_) {
    const std::size_t c = grid.flat(cell_of(P.x[p] / grid.dx));
    v.jbar = cell_[2 * c];
    v.wsum = cell_[2 * c + 1];
    if (!nodal_total_.empty()) {
      // Relaxed towards the stencil's whole-volume average at the rate 1/τ (a particle whose
      // stencil carries none, towards its own).
      const Vec<2> st = stencil_sums(grid, w);  // nodal_ holds (T̄, has one) now
      const double target = st[1] > 0.0 ? st[0] / st[1] : v.dj;
      const double a = std::min(1.0, dt / relaxation_time_);
      v.jbar = (1.0 - a) * v.jbar + a * target;
    }
    return v;
  }
  const Vec<2> sums = stencil_sums(grid, w);
  v.jbar = sums[0];
  v.wsum = sums[1];
  return v;
}

extern template class VolumeAverage<2>;
extern template class VolumeAverage<3>;

}  // namespace crevasse
