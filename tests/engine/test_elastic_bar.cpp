// Elastic wave speed. A laterally confined bar (free-slip walls on its lateral faces) moving at
// V0 hits a rigid wall (box_walls on x) at t = 0. Classical 1D impact: a compressive step
// −ρ c_p V0 runs up the bar at c_p = sqrt((λ + 2μ)/ρ), reflects from the free end as an
// unloading wave and returns at t = 2L/c_p, when the bar leaves the wall at +V0. The wall force
// is constant, ρ c_p V0 A, so the bar's momentum goes linearly from −M V0 to +M V0 and crosses
// zero at t = L/c_p.
// Why this set-up rather than a free-free vibration: the walls are one-sided (they remove only
// velocity into the wall), so they confine a bar in compression but not in tension, and a
// vibrating bar would alternate between the confined modulus λ + 2μ and the unconfined one.
// Throughout the impact the bar is only ever compressed (stress −ρ c_p V0 or 0), so the walls
// hold it in uniaxial strain exactly and the analytic speed is the P-wave speed.
// Two measurements: the zero-crossing time of the momentum (L/c_p) and the slope of the
// momentum during contact (the wall force ρ c_p V0 A), each giving c_p.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "engine/simulation.hpp"
#include "scene_builders.hpp"

namespace crevasse {
namespace {

using test::box_scene;
using test::finish;

constexpr double kLength = 80.0;  // 80 cells: the wall and the bar end are each known to ~dx/2
constexpr double kDx = 1.0;
constexpr double kSide = 2.0;  // lateral size [m] (2 cells)
constexpr double kV0 = 1.0;    // impact speed [m/s]: strain V0/c_p ≈ 1e-3, small

struct Impact {
  double c_from_crossing = 0.0;
  double c_from_force = 0.0;
  double rebound_speed = 0.0;
  double c_p = 0.0;
};

template <int Dim>
Impact impact() {
  std::array<double, 3> hi{kLength, kSide, 0.0}, dlo{0.0, 0.0, 0.0},
      dhi{kLength + 40.0, kSide, 0.0};
  std::vector<int> walls{0, 1};
  if (Dim == 3) {
    hi = {kLength, kSide, kSide};
    dhi = {kLength + 40.0, kSide, kSide};
    walls = {0, 1, 2};
  }
  SceneConfig s = box_scene(Dim, {0, 0, 0}, hi, dlo, dhi, {Effect::box_walls}, kDx);
  s.wall_axes = walls;
  s = finish(s);
  Simulation<Dim> sim(s);
  auto& P = sim.mutable_particles();
  for (auto& v : P.v) v[0] = -kV0;
  const double mass = sim.total_mass();
  double area = kSide;
  if (Dim == 3) area *= kSide;
  const double t_contact = 2.0 * kLength / s.p_wave_speed();
  Impact r;
  r.c_p = s.p_wave_speed();
  std::vector<double> t, mom;
  double prev_t = 0.0, prev_m = -mass * kV0;
  while (sim.time() < 1.3 * t_contact) {
    sim.step();
    const double m = sim.total_momentum()[0];
    if (prev_m < 0.0 && m >= 0.0) {
      const double t0 = prev_t + (sim.time() - prev_t) * (-prev_m) / (m - prev_m);
      r.c_from_crossing = kLength / t0;
    }
    // Slope over the middle of the contact, away from the start and end transients.
    if (sim.time() > 0.2 * t_contact && sim.time() < 0.8 * t_contact) {
      t.push_back(sim.time());
      mom.push_back(m);
    }
    prev_t = sim.time();
    prev_m = m;
  }
  const double force = test::fit_line(t, mom)[1];
  r.c_from_force = force / (test::kRho * kV0 * area);
  r.rebound_speed = sim.total_momentum()[0] / mass;
  return r;
}

// 3%: the acceptance tolerance. Measured errors are below 1%; the sources are the position of
// the wall and of the free end, each uncertain by ~dx/2 over L = 80 dx (~0.6%), and the
// dispersion of the step front (which does not move the momentum balance). An unconfined bar
// would give the bar speed sqrt(E/(ρ(1−ν²))) in plane strain, 10% slower: the test tells the
// two apart.
constexpr double kWaveTolerance = 0.03;

template <int Dim>
void check_impact() {
  const Impact r = impact<Dim>();
  const double e_cross = std::abs(r.c_from_crossing - r.c_p) / r.c_p;
  const double e_force = std::abs(r.c_from_force - r.c_p) / r.c_p;
  std::cout << Dim << "D: c_p " << r.c_p << " m/s; from momentum zero-crossing "
            << r.c_from_crossing << " (rel. error " << e_cross << "); from wall force "
            << r.c_from_force << " (rel. error " << e_force << "); rebound speed "
            << r.rebound_speed << " m/s\n";
  EXPECT_LT(e_cross, kWaveTolerance);
  EXPECT_LT(e_force, kWaveTolerance);
  // Elastic rebound at +V0. 5%: the numerical dissipation of the step front (APIC transfers)
  // costs some kinetic energy; measured 1.9% of the speed.
  EXPECT_NEAR(r.rebound_speed, kV0, 0.05 * kV0);
}

TEST(ElasticBar, ImpactWaveSpeed2d) { check_impact<2>(); }
TEST(ElasticBar, ImpactWaveSpeed3d) { check_impact<3>(); }

}  // namespace
}  // namespace crevasse
