#pragma once
// The effects a scene applies to each particle right after its update, in this order: the
// projection out of the bed (scenes with basal friction), the piston's layer (piston-driven
// scenes) and the clamp to the domain (every scene). The update sweep applies them as it writes
// each particle, so a particle is read and written once per step.
// Reads and writes the particle's x, v and C.
#include <algorithm>
#include <cmath>

#include "engine/bed_field.hpp"
#include "engine/particles.hpp"

namespace crevasse {

template <int Dim>
struct ParticleEffects {
  bool bed = false, piston = false;
  double piston_shift = 0.0, piston_speed = 0.0;  // the piston's place and speed at the end of the step
  Vec<Dim> lo, hi;                                // the domain

  [[gnu::always_inline]] inline void apply(Particles<Dim>& P, std::size_t p, const BedField<Dim>& bed_field) const {
    if (bed) bed_field.project_out(P.x[p]);
    if (piston && !std::isnan(P.drive_x0[p])) {
      // The piston is the back layer of ice (one cell thick), moved kinematically along x at the
      // drive speed and free to slide vertically. A grid-node wall instead gives the ice an
      // impulse each time its face crosses a node column, which builds a grid-scale stress
      // oscillation behind the face (seen as tensile bands that crack the back of the slab).
      P.x[p][0] = P.drive_x0[p] + piston_shift;
      P.v[p][0] = piston_speed;
      P.C[p].row(0).setZero();
    }
    for (int a = 0; a < Dim; ++a) P.x[p][a] = std::clamp(P.x[p][a], lo[a], hi[a]);
  }
};

}  // namespace crevasse
