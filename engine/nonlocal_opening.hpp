#pragma once
// Nonlocal opening (docs/model.md, "Softening with a length"): the cap and the shear strength
// soften with ε̂_p = m·ε̄_p + (1 − m)·ε_v^p instead of the particle's own ε_v^p, where ε̄ is
// the mass-weighted average of ε_v^p over a disc (ball in 3D) of radius R with the bell weight
// (1 − r²/R²)² (Pijaudier-Cabot & Bažant 1987, J. Eng. Mech. 113:1512; m > 1 is the
// "over-nonlocal" form of Vermeer & Brinkgreve 1994, which Jirásek & Rolshoven 2003, IJES 41:2239,
// show regularises softening plasticity fully where m = 1 can leave a band one cell wide).
// A damaged band then has a width set by R, not by dx.
//
// Computed on the grid each step, before P2G: (1) one coloured sweep scatters m ε_v^p and m with
// the quadratic weights; (2) per node, the bell-weighted sums over the nodes within R; (3) per
// particle, the stencil-weighted gather of the nodal averages. The softening is explicit in it:
// the return mapping holds e^{−ζ ε̂} fixed over the step (CappedVonMisesParams::explicit_softening).
#include <cstddef>
#include <vector>

#include "engine/grid.hpp"
#include "engine/particle_colouring.hpp"
#include "engine/particles.hpp"

namespace crevasse {

template <int Dim>
class NonlocalOpening {
 public:
  NonlocalOpening() = default;
  // radius R [m] (0 = off), weight m [-], on a grid of spacing dx.
  NonlocalOpening(double radius, double weight, double dx);
  bool active() const { return radius_ > 0.0; }
  double radius() const { return radius_; }

  // Reads x, mass, ε_v^p; writes ε̂ of every particle (at()).
  void compute(const Particles<Dim>& P, const Grid<Dim>& grid, const ParticleColouring<Dim>& colouring);
  double at(std::size_t p) const { return eps_hat_[p]; }
  const double* values() const { return eps_hat_.data(); }

 private:
  struct Offset {
    IVec<Dim> node;
    double weight;
  };
  double radius_ = 0.0;
  double weight_ = 1.0;
  std::vector<Offset> offsets_;  // the nodes within R of a node, with their bell weights
  std::vector<double> nodal_;    // per node (Σ w m ε_v^p, Σ w m)
  std::vector<double> averaged_; // per node ε̄ (0 where no ice)
  std::vector<double> eps_hat_;  // per particle ε̂
};

extern template class NonlocalOpening<2>;
extern template class NonlocalOpening<3>;

}  // namespace crevasse
