#pragma once
// Hard cases (docs/model.md, "Numerics"): runs a scene step by step and checks,
// while it runs and at the end, what a stable run must satisfy.
//
//  * finite: positions, velocities, F_E and the Kirchhoff stress of every particle;
//  * mass: what is left plus what the outflow removed equals the initial mass (round-off);
//  * domain: no particle outside [domain_min, domain_max];
//  * kinetic energy bounded by a stated multiple of the drive's input (below);
//  * yield: Φ/c ≤ kYieldTolerance at every particle at the end (Simulation::max_yield_violation).
//
// Kinetic-energy bound. The drive's input is E_drive = ½ M₀ V_x², the kinetic energy of all the
// ice moving at the drive speed. A particle can be faster than V_x for two reasons only:
//  1. the push: a compression wave from the piston carries particle speed ≤ V_x, and its
//     reflection at a free face doubles it, so ≤ 2 V_x;
//  2. gravity: a particle can fall at most from the top of the ice on the plateau to the floor
//     past the step, H_s + H_i, and gains at most sqrt(2 g (H_s + H_i)).
// (The elastic energy stored in the geostatic start, σ²/(2 E ρ) per unit mass with σ ≤ ρ g H_i,
// is below 0.1 m²/s² for H_i ≤ 1000 m and is left out.) So every particle keeps
// |v| ≤ v_max = 2 V_x + sqrt(2 g (H_s + H_i)) and
//     KE(t) ≤ ½ M₀ v_max² = k · E_drive,   k = (2 + sqrt(2 g (H_s + H_i))/V_x)².
// The run fails the check when KE exceeds that at any step; a blow-up exceeds it by orders of
// magnitude within a few steps. The largest particle speed is compared with v_max as well.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>

#include "engine/error.hpp"
#include "engine/scene.hpp"
#include "engine/simulation.hpp"

namespace crevasse::test {

inline constexpr double kYieldTolerance = 1e-6;  // Φ/c

struct HardResult {
  std::int64_t steps = 0;
  double sim_time = 0.0;
  double wall_s = 0.0;
  double initial_mass = 0.0, final_mass = 0.0, removed_mass = 0.0, inflow_mass = 0.0;
  std::size_t initial_particles = 0, final_particles = 0;
  double ke_bound_factor = 0.0;  // k above
  double max_ke_ratio = 0.0;     // max over steps of KE / E_drive
  double max_speed = 0.0;        // max over steps of the largest particle speed [m/s]
  double v_max = 0.0;            // the bound on it [m/s]
  double yield_violation = 0.0;  // Φ/c at the end (max over particles)
  std::size_t non_finite = 0;    // particles with a non-finite state at the end
  std::size_t outside = 0;       // particles outside the domain (max over checks)
  std::string first_bad;         // description of the first bad particle found
};

inline double ke_bound_factor(const SceneConfig& s) {
  return std::pow(2.0 + std::sqrt(2.0 * s.gravity * (s.step_height + s.ice_thickness)) / s.drive_speed, 2);
}

template <int Dim>
std::size_t count_outside(const Simulation<Dim>& sim, std::string* first) {
  const auto& P = sim.particles();
  const SceneConfig& s = sim.scene();
  std::size_t n = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    for (int a = 0; a < Dim; ++a) {
      if (!(P.x[p][a] >= s.domain_min[a] && P.x[p][a] <= s.domain_max[a])) {
        if (n == 0 && first) {
          std::ostringstream o;
          o << "particle " << p << " outside the domain on axis " << a << ": " << P.x[p][a];
          *first = o.str();
        }
        ++n;
        break;
      }
    }
  }
  return n;
}

template <int Dim>
std::size_t count_non_finite(const Simulation<Dim>& sim, std::string* first) {
  const auto& P = sim.particles();
  std::size_t n = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const bool ok = P.x[p].allFinite() && P.v[p].allFinite() && P.tau[p].allFinite() &&
                    P.F_e[p].allFinite() && P.C[p].allFinite() &&
                    (!P.has_plastic_state() || std::isfinite(P.eps_v_p[p]));
    if (!ok) {
      if (n == 0 && first) *first = "particle " + std::to_string(p) + " has a non-finite state";
      ++n;
    }
  }
  return n;
}

// Runs `scene` (resolved; its end_time is the stop) and returns what the checks need. The
// domain is checked every `check_every` steps and at the end; KE and speed every step.
template <int Dim>
HardResult run_hard_case(const SceneConfig& scene, int check_every = 50) {
  const auto t0 = std::chrono::steady_clock::now();
  Simulation<Dim> sim(scene);
  HardResult r;
  r.initial_mass = sim.total_mass();
  r.initial_particles = sim.particles().size();
  r.ke_bound_factor = ke_bound_factor(scene);
  r.v_max = 2.0 * scene.drive_speed + std::sqrt(2.0 * scene.gravity * (scene.step_height + scene.ice_thickness));
  const double e_drive = 0.5 * r.initial_mass * scene.drive_speed * scene.drive_speed;
  sim.settle();
  while (sim.time() < scene.end_time && sim.particles().size() > 0) {
    sim.step();
    r.max_ke_ratio = std::max(r.max_ke_ratio, sim.kinetic_energy() / e_drive);
    double v2 = 0.0;
    for (const auto& v : sim.particles().v) v2 = std::max(v2, v.squaredNorm());
    r.max_speed = std::max(r.max_speed, std::sqrt(v2));
    if (sim.steps() % check_every == 0)
      r.outside = std::max(r.outside, count_outside(sim, r.first_bad.empty() ? &r.first_bad : nullptr));
  }
  r.outside = std::max(r.outside, count_outside(sim, r.first_bad.empty() ? &r.first_bad : nullptr));
  r.non_finite = count_non_finite(sim, r.first_bad.empty() ? &r.first_bad : nullptr);
  r.steps = sim.steps();
  r.sim_time = sim.time();
  r.final_mass = sim.total_mass();
  r.removed_mass = sim.removed_mass();
  r.inflow_mass = sim.inflow_mass();
  r.final_particles = sim.particles().size();
  r.yield_violation = sim.particles().size() ? sim.max_yield_violation() : 0.0;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

inline HardResult run_hard_case(const SceneConfig& scene, int check_every = 50) {
  return scene.dim == 3 ? run_hard_case<3>(scene, check_every) : run_hard_case<2>(scene, check_every);
}

// The assertions every hard case makes; also records the numbers in the test's XML output.
inline void expect_stable(const SceneConfig& scene, const HardResult& r,
                          double yield_tolerance = kYieldTolerance) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  ::testing::Test::RecordProperty("steps", std::to_string(r.steps));
  ::testing::Test::RecordProperty("particles", std::to_string(r.initial_particles));
  ::testing::Test::RecordProperty("max_ke_ratio", std::to_string(r.max_ke_ratio));
  ::testing::Test::RecordProperty("yield_violation", std::to_string(r.yield_violation));
  std::printf("[hard] %s: steps %lld, t %.1f s, wall %.2f s, particles %zu -> %zu, max KE/E_drive %.3g "
              "(bound %.3g), max speed %.3g m/s (bound %.3g), Phi/c %.3g\n",
              info ? info->name() : "?", static_cast<long long>(r.steps), r.sim_time, r.wall_s,
              r.initial_particles, r.final_particles, r.max_ke_ratio, r.ke_bound_factor, r.max_speed,
              r.v_max, r.yield_violation);
  EXPECT_GE(r.sim_time, scene.end_time * (1 - 1e-12)) << "the run stopped early (no ice left?)";
  EXPECT_EQ(r.non_finite, 0u) << r.first_bad;
  EXPECT_EQ(r.outside, 0u) << r.first_bad;
  EXPECT_NEAR(r.final_mass + r.removed_mass, r.initial_mass + r.inflow_mass, 1e-12 * r.initial_mass);
  EXPECT_LE(r.max_ke_ratio, r.ke_bound_factor) << "kinetic energy above k·E_drive";
  EXPECT_LE(r.max_speed, r.v_max) << "a particle faster than 2 V_x + sqrt(2 g (H_s + H_i))";
  EXPECT_LE(r.yield_violation, yield_tolerance) << "Φ/c > tolerance at the end";
}

}  // namespace crevasse::test
