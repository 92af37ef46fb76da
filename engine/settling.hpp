#pragma once
// The settling phase (numerics settle_time, engine/scene.hpp): before t = 0 the ice settles
// elastically, with the drive at rest and its grid velocity damped at the rate γ = c_p/H,
// near-critical for its first vertical mode. Damping exists only while settling: one branch
// per step, none per particle.
#include <cmath>

#include "engine/grid.hpp"
#include "engine/particles.hpp"
#include "engine/scene.hpp"

namespace crevasse {

struct Settling {
  bool active = false;        // stepping before t = 0
  bool done = false;          // the phase has ended (or the scene has none)
  double damping_rate = 0.0;  // γ [1/s]

  // γ = c_p over the ice's height (the slab's thickness, the box's extent).
  template <int Dim>
  static double damping_rate_of(const SceneConfig& scene) {
    return scene.p_wave_speed() / (scene.body == Body::slab
                                       ? scene.ice_thickness
                                       : scene.box_max[Dim - 1] - scene.box_min[Dim - 1]);
  }

  // Reads and writes the nodes' velocity.
  template <int Dim>
  void damp(Grid<Dim>& grid, double dt) const {
    if (!active) return;
    const double f = std::exp(-damping_rate * dt);
    for (auto& g : grid.nodes) g.vel *= f;
  }
};

// drive.start "moving": the settled glacier is set sliding as a rigid body at V_x, the speed the
// drives hold from t = 0. A rigid translation carries no stress, so the start sends no wave
// through the ice, however long it is. Ice over the ramp then settles onto its bed under
// gravity; a start with each column already following the bed (v_z = V_x z_b'(x)) has a jump of
// v_z at the lip and the foot, and cracked both at once (twice the damaged particles after 1 s
// at H_i = 200 m). Writes v.
template <int Dim>
void set_sliding(Particles<Dim>& P, double speed) {
  for (std::size_t p = 0; p < P.size(); ++p) P.v[p][0] = speed;
}

}  // namespace crevasse
