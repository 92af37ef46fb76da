#pragma once
// Small scenes for the engine tests, built in code. Every builder returns a resolve()d
// SceneConfig; callers change fields and call resolve() again only through finish().
#include <algorithm>
#include <array>
#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include "engine/scene.hpp"
#include "engine/simulation.hpp"

namespace crevasse::test {

// Ice properties shared by the tests (docs/model.md defaults for E, ν, ρ).
constexpr double kRho = 917.0;
constexpr double kYoung = 1.0e9;
constexpr double kPoisson = 0.3;
constexpr double kG = 9.81;

// A shipped scene file (studies/scenes/), as JSON to patch before scene_from_json; VTU output
// off so tests write nothing.
inline nlohmann::json shipped_scene_json(const std::string& file = "glacier_2d.json") {
  std::ifstream f(std::string(CREVASSE_SOURCE_DIR) + "/studies/scenes/" + file);
  nlohmann::json j = nlohmann::json::parse(f);
  j["output"]["vtu_interval"] = 0.0;
  return j;
}

// A box of ice [lo, hi] inside the domain [domain_lo, domain_hi] (only the first dim entries
// are used), starting unstressed, with the given effects. Run control: a large max_steps, as
// the tests drive step() themselves.
inline SceneConfig box_scene(int dim, std::array<double, 3> lo, std::array<double, 3> hi,
                             std::array<double, 3> domain_lo, std::array<double, 3> domain_hi,
                             std::initializer_list<Effect> effects, double dx) {
  SceneConfig s;
  s.name = "test_box";
  s.dim = dim;
  s.effects = effects;
  s.body = Body::box;
  s.box_min = lo;
  s.box_max = hi;
  s.domain_min = domain_lo;
  s.domain_max = domain_hi;
  s.bed_shape = BedShape::none;
  s.initial_stress = InitialStress::none;
  s.density = kRho;
  s.youngs_modulus = kYoung;
  s.poisson_ratio = kPoisson;
  s.gravity = kG;
  s.dx = dx;
  s.max_steps = 1000000000;
  return s;
}

// A small glacier pushed over a step: the scene of studies/scenes/glacier_2d.json (effects
// gravity, drive, basal_friction, plasticity, softening, outflow; lateral_walls in 3D;
// geostatic start; ζ from the crack-band reference) on a coarse grid (by default the coarsest
// the validation allows, dx = H_i/4) and a short domain, so that a run takes seconds. Lengths are in units of H_i;
// the tensile strength is given as Π = c/(ρ_i g H_i).
struct SmallGlacier {
  int dim = 2;
  double thickness = 50.0;          // H_i [m]
  double step_height_ratio = 1.0;   // H_s/H_i
  double step_length_ratio = 1.0;   // L_s/H_i (0: vertical step; slope = H_s/L_s)
  double upstream_ratio = 3.0;      // slab length on the plateau / H_i
  double downstream_ratio = 4.0;    // floor past the step / H_i
  double width_ratio = 1.0;         // W_i/H_i (3D)
  double cohesion_ratio = 0.2;      // Π
  double drive_speed = 4.0;         // V_x [m/s]
  double cells_per_thickness = 4.0;  // H_i/dx (≥ 4)
  double cfl = 0.5;
  double end_time = 60.0;           // [s]
};

inline SceneConfig small_glacier_scene(const SmallGlacier& g) {
  SceneConfig s;
  s.name = "small_glacier";
  s.dim = g.dim;
  s.effects = {Effect::gravity, Effect::drive, Effect::basal_friction, Effect::plasticity,
               Effect::softening, Effect::outflow};
  if (g.dim == 3) s.effects.push_back(Effect::lateral_walls);
  s.body = Body::slab;
  s.initial_stress = InitialStress::geostatic;
  s.density = kRho;
  s.youngs_modulus = kYoung;
  s.poisson_ratio = kPoisson;
  s.gravity = kG;
  s.ice_thickness = g.thickness;
  s.upstream_length = g.upstream_ratio * g.thickness;
  s.width = g.width_ratio * g.thickness;
  s.tensile_strength = g.cohesion_ratio * kRho * kG * g.thickness;
  s.bed_shape = BedShape::step;
  s.step_height = g.step_height_ratio * g.thickness;
  s.step_length = g.step_length_ratio * g.thickness;
  s.downstream_length = g.downstream_ratio * g.thickness;
  s.drive_speed = g.drive_speed;
  s.dx = g.thickness / g.cells_per_thickness;
  s.cfl = g.cfl;
  s.end_time = g.end_time;
  s.png = false;
  s.resolve();
  return s;
}

// A bar of ice (plane strain, length × thickness, free faces, no gravity) held by two rigid grips
// `grip` long that move apart at ±speed (velocity_boundaries), c = 1 MPa, q_y = 10 MPa, ζ from
// the crack-band reference ζ = 500·dx/(1 m). Not yet resolved: the caller sets what it varies
// and calls finish().
inline SceneConfig pulled_bar_scene(double length, double thickness, double grip, double speed, double dx) {
  SceneConfig s = box_scene(2, {0, 0, 0}, {length, thickness, 0}, {-4, -2, 0}, {length + 4, thickness + 2, 0},
                            {Effect::plasticity, Effect::softening, Effect::velocity_boundaries}, dx);
  s.tensile_strength = 1.0e6;
  s.shear_strength = 1.0e7;
  s.zeta_ref = 500.0;
  s.dx_ref = 1.0;
  s.softening_zeta = 0.0;
  VelocityBox left, right;
  left.min = {-10, -10, 0};
  left.max = {grip, 10, 0};
  left.velocity = {-speed, 0, 0};
  right.min = {length - grip, -10, 0};
  right.max = {length + 10, 10, 0};
  right.velocity = {speed, 0, 0};
  s.velocity_boxes = {left, right};
  return s;
}

inline SceneConfig finish(SceneConfig s) {
  s.resolve();
  return s;
}

// Lamé parameters and wave speeds of the test ice.
inline double lame_mu() { return kYoung / (2.0 * (1.0 + kPoisson)); }
inline double lame_lambda() {
  return kYoung * kPoisson / ((1.0 + kPoisson) * (1.0 - 2.0 * kPoisson));
}
// P-wave (constrained, uniaxial-strain) modulus λ + 2μ and speed.
inline double p_wave_modulus() { return lame_lambda() + 2.0 * lame_mu(); }

inline bool has_stage(const std::vector<StageStats>& stages, const std::string& name) {
  for (const auto& s : stages)
    if (s.name == name) return true;
  return false;
}

// Least-squares line y = a + b x; returns {a, b}.
inline std::array<double, 2> fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  const double b = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  return {(sy - b * sx) / n, b};
}

// Column under gravity: steps `sim` to t_end and returns the time average of the linear fit
// σ_zz(z) = a + b z over the particles away from the bottom and top cells (where the discrete
// stress departs from the line). Each step's fit is weighted by the step that produced it, the
// last trimmed to end at t_end, so averaging over whole periods removes the oscillation.
template <int Dim>
std::array<double, 2> time_averaged_stress_line(Simulation<Dim>& sim, double t_end, double dx,
                                                double height) {
  double a_sum = 0.0, b_sum = 0.0, t_sum = 0.0;
  std::vector<double> z, szz;
  while (sim.time() < t_end) {
    sim.step();
    const double w = std::min(sim.last_dt(), t_end - (sim.time() - sim.last_dt()));
    const ParticleSnapshot snap = sim.snapshot();
    z.clear();
    szz.clear();
    for (std::size_t i = 0; i < snap.size(); ++i) {
      if (snap.z[i] < dx || snap.z[i] > height - dx) continue;
      z.push_back(snap.z[i]);
      szz.push_back(snap.sigma_zz_pa[i]);
    }
    const auto line = fit_line(z, szz);
    a_sum += w * line[0];
    b_sum += w * line[1];
    t_sum += w;
  }
  return {a_sum / t_sum, b_sum / t_sum};
}

}  // namespace crevasse::test
