#pragma once
// A plain, dimension-free copy of the particle state at one instant: what output writers
// (VTU), the crevasse measurement and the side-view figures read. Engine internals stay
// behind Simulation<Dim>; this is the only particle data that crosses into analysis/.
#include <array>
#include <string>
#include <vector>

namespace crevasse {

struct ParticleSnapshot {
  int dim = 2;                 // 2: (x, z); 3: (x, y, z). z is up, x along flow.
  double time_s = 0.0;         // simulated time [s]
  double dx_m = 0.0;           // background grid spacing [m]
  double softening_zeta = 0.0; // ζ in p_c = −c·exp(−ζ ε_v^p); 0 when softening is off
  double tensile_strength_pa = 0.0;  // c [Pa]
  double ice_thickness_m = 0.0;      // H_i [m]
  double step_top_x_m = 0.0;   // x where the bed starts to drop (top of the step) [m]
  double step_foot_x_m = 0.0;  // x where the ramp meets the downstream floor [m]
  double particle_spacing_m = 0.0;   // initial spacing between particles along an axis [m]

  // Bed profile z_b(x) as a polyline of (x, z) vertices, for drawing and surface checks.
  std::vector<std::array<double, 2>> bed_profile;

  // One entry per particle. y is empty in 2D.
  std::vector<double> x, y, z;        // position [m]
  std::vector<double> vx, vy, vz;     // velocity [m/s] (vy empty in 2D)
  std::vector<double> eps_v_p;        // accumulated volumetric plastic strain ε_v^p [-]
  std::vector<double> pressure_pa;    // p = −tr(τ)/d, compression positive [Pa]
  std::vector<double> von_mises_pa;   // q = sqrt(3/2 dev τ : dev τ) [Pa]
  std::vector<double> sigma_zz_pa;    // vertical Cauchy stress, tension positive [Pa]
  std::vector<double> volume_m3;      // current volume (area in 2D, per unit depth) [m^3]

  // Measurement gate (empty when the scene records none): one record per particle that has
  // reached x ≥ gate_x_m, including particles since removed by the outflow: its initial
  // position and its ε_v^p at the moment it reached the gate (docs/measurement.md).
  double gate_x_m = 0.0;
  double gate_passed_length_m = 0.0;  // ice length along flow that has passed the gate [m]
  std::vector<double> gate_x_ref, gate_y_ref, gate_z_ref, gate_eps_v_p;
  bool has_gate() const { return !gate_eps_v_p.empty(); }

  std::size_t size() const { return x.size(); }
  // Fraction of strength lost, 1 − exp(−ζ ε_v^p) (docs/measurement.md); 0 with softening off.
  double damage(std::size_t i) const;
  // Front of the connected ice (Simulation::ice_front_x) when the engine filled it in (> 0);
  // scattered debris ahead of the ice does not move it.
  double ice_front_x_m = 0.0;
  // Most downstream x of the ice that started upstream of the top of the step, i.e. that came
  // over the step during the run (0 when the scene keeps no initial positions: no gate).
  double upstream_ice_front_x_m = 0.0;
  // The ice front [m]: ice_front_x_m when set, else the x of the most downstream particle.
  double front_x() const;
};

}  // namespace crevasse
