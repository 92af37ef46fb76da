// The flowing glacier (studies/scenes/flowing_2d.json): ice draped over the whole bed, set
// sliding at V_x once settled, pushed at its back and held at V_x where it leaves downstream.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "engine/simulation.hpp"
#include "scene_builders.hpp"

namespace crevasse {
namespace {

TEST(FlowingGlacier, DrapedIceReachesTheOutflowLineByDefault) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json("flowing_2d.json"));
  EXPECT_DOUBLE_EQ(scene.draped_length, scene.step_length + scene.downstream_length - 3.0 * scene.dx);
  EXPECT_EQ(scene.drive_ramp_time, 0.0);  // no ramp: the start does not grow with L_up
  EXPECT_EQ(scene.drive_velocity(0.0), scene.drive_speed);
  EXPECT_EQ(scene.drive_position(10.0), 10.0 * scene.drive_speed);
}

TEST(FlowingGlacier, SettledGlacierStartsAsARigidSlideAtTheDriveSpeed) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json("flowing_2d.json"));
  Simulation<2> sim(scene);
  sim.settle();
  const auto& P = sim.particles();
  for (std::size_t p = 0; p < P.size(); ++p) {
    ASSERT_EQ(P.v[p][0], scene.drive_speed) << p;
    ASSERT_EQ(P.v[p][1], 0.0) << p;
  }
}

// Particles whose whole stencil (1.5 cells either side) lies in the held cells gather exactly
// (V_x, 0); without the downstream drive the ice there moves with what pushes it.
TEST(FlowingGlacier, IceAtTheDownstreamEndMovesAtTheDriveSpeed) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json("flowing_2d.json"));
  Simulation<2> sim(scene);
  sim.settle();
  while (sim.time() < 5.0) sim.step();
  const double x_held = scene.domain_max[0] - 5.0 * scene.dx + 1.5 * scene.dx;
  const auto& P = sim.particles();
  int checked = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (P.x[p][0] < x_held) continue;
    EXPECT_NEAR(P.v[p][0], scene.drive_speed, 1e-9) << P.x[p][0];
    EXPECT_NEAR(P.v[p][1], 0.0, 1e-9) << P.x[p][0];
    ++checked;
  }
  EXPECT_GE(checked, 10);
}

// docs/model.md: a fracture at t = 0 is a bug. The draped glacier at rest (drive speed 0, both ends
// held), settled, then run with its full material law: no particle opens, and none is outside
// the yield surface. (Without the hold, the free end of the floor ice is a cliff H_i high and
// fails under its own weight: 821 particles opened in 20 s.)
// Settled and run 20 s: no particle has opened and every stress is inside the yield surface.
void expect_nothing_opens_in_20_s(const SceneConfig& scene) {
  Simulation<2> sim(scene);
  sim.settle();
  while (sim.time() < 20.0) sim.step();
  const auto& P = sim.particles();
  int opened = 0;
  for (std::size_t p = 0; p < P.size(); ++p) opened += P.eps_v_p[p] > 0.0;
  EXPECT_EQ(opened, 0);
  EXPECT_LE(sim.max_yield_violation(), 1e-9);
}

TEST(FlowingGlacier, DrapedGlacierWithoutDriveShowsNoDamageAfterSettling) {
  nlohmann::json j = test::shipped_scene_json("flowing_2d.json");
  j["drive"]["speed"] = 0.0;
  const SceneConfig scene = scene_from_json(j);
  expect_nothing_opens_in_20_s(scene);
}

// The same on the quick study's start (studies/scenes/flowing_weight_cell_2d.json: the inflow
// scene with the relaxed per-cell whole-volume average) at rest: inflow speed 0, gravity not tilted, so nothing drives it.
TEST(FlowingGlacier, InflowGlacierWithTheWholeVolumeAverageShowsNoDamageAtRest) {
  nlohmann::json j = test::shipped_scene_json("flowing_weight_cell_2d.json");
  j["drive"]["speed"] = 0.0;
  j["gravity"]["tilt_deg"] = 0.0;
  const SceneConfig scene = scene_from_json(j);
  ASSERT_TRUE(scene.average_total_volume);
  ASSERT_TRUE(scene.average_per_cell);
  expect_nothing_opens_in_20_s(scene);
}

// Nothing downstream carries the glacier (docs/model.md, "Boundaries"): over 20 s of the pushed
// scene (studies/scenes/pushed_2d.json) with a shear strength that does not bind (10 ρ_i g H_i),
// the vertical impulse the domain's downstream end gives the ice stays below 0.1 % of the ice's
// weight times the run time. Held nodes there (downstream_drive, the older scenes' end) already
// give 0.6 % over these first 20 s, before the strong glacier reaches them as a bridge (measured;
// in longer runs a glacier that does not yield bridges the step on them): the same run with
// them must fail the bound, which the test checks too, so the bound measures something.
double downstream_impulse_over_weight_time(bool held) {
  nlohmann::json j = test::shipped_scene_json("pushed_2d.json");
  const double h = j["ice"]["thickness"].get<double>();
  j["ice"]["shear_strength"] = 10.0 * j["ice"]["density"].get<double>() * j["gravity"]["g"].get<double>() * h;
  // Draped to the domain's end in both runs, so that ice lies in the end's cells from the start
  // and the free end is measured where it could carry the ice; only the held nodes differ.
  j["ice"]["draped_length"] = 0.0;
  if (held) j["effects"].push_back("downstream_drive");
  const SceneConfig scene = scene_from_json(j);
  Simulation<2> sim(scene);
  sim.settle();
  const double t0 = sim.time();
  double weight_time = 0.0;
  while (sim.time() < t0 + 20.0) {
    const double weight = sim.total_mass() * scene.gravity;
    sim.step();
    weight_time += weight * sim.last_dt();
  }
  return sim.downstream_impulse_z() / weight_time;
}

TEST(FlowingGlacier, NothingDownstreamCarriesThePushedGlacier) {
  const double free_end = downstream_impulse_over_weight_time(false);
  EXPECT_LT(std::abs(free_end), 1e-3) << free_end;
  const double held_end = downstream_impulse_over_weight_time(true);
  EXPECT_GT(held_end, 1e-3) << "held nodes must fail the bound, else it measures nothing";
}

// The passed frame's window ends at the front of the ice that started upstream of the top of the
// step (docs/measurement.md): at the start that ice ends at the lip, and the drive carries it on
// at about V_x, while the ice draped past the lip lies ahead of it.
TEST(FlowingGlacier, UpstreamIceFrontFollowsTheIceThatStartedBeforeTheLip) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json("pushed_2d.json"));
  Simulation<2> sim(scene);
  sim.settle();
  const double top = scene.step_top_x();
  const ParticleSnapshot start = sim.snapshot();
  EXPECT_GT(start.front_x(), top + scene.ice_thickness);  // draped ice ahead of it
  EXPECT_LE(start.upstream_ice_front_x_m, top);
  EXPECT_GE(start.upstream_ice_front_x_m, top - scene.dx);
  const double t0 = sim.time();
  while (sim.time() < t0 + 10.0) sim.step();
  const double moved = sim.snapshot().upstream_ice_front_x_m - start.upstream_ice_front_x_m;
  EXPECT_NEAR(moved, scene.drive_speed * 10.0, 0.5 * scene.drive_speed * 10.0);
}

// "hydrostatic" loads the cryostatic state σ = −ρ g (s − z) I: no deviatoric stress at rest, so a
// shear strength below the K0 state's q = (1 − 2ν)/(1 − ν)·ρ g (s − z) does not yield at t = 0.
TEST(FlowingGlacier, HydrostaticStartHasNoDeviatoricStress) {
  nlohmann::json j = test::shipped_scene_json("flowing_2d.json");
  j["ice"]["initial_stress"] = "hydrostatic";
  const SceneConfig scene = scene_from_json(j);
  Simulation<2> sim(scene);
  const auto& P = sim.particles();
  const double rho_g = scene.density * scene.gravity;
  const double top = scene.step_height + scene.ice_thickness;
  int checked = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (P.x[p][0] > scene.step_top_x() - scene.dx) continue;  // the plateau, where s = H_s + H_i
    const double j_det = P.F_e[p].determinant();
    const double expected = -rho_g * (top - P.x[p][1]);
    ASSERT_NEAR(P.tau[p](0, 0) / j_det, expected, 1e-6 * rho_g * scene.ice_thickness) << p;
    ASSERT_NEAR(P.tau[p](1, 1) / j_det, expected, 1e-6 * rho_g * scene.ice_thickness) << p;
    ASSERT_EQ(P.tau[p](0, 1), 0.0) << p;
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

// What the hydrostatic start is for: a glacier at rest (drive speed 0, both ends held) whose shear
// strength, 0.3 ρ g H_i, is below the K0 state's q at depths past 0.53 H_i. Settled, then one
// step with its full law, the plateau's interior (1–3 H_i from the piston, 2 H_i and more from
// the lip) stays inside the yield surface: its largest q is 0.67 q_y (a flat slab would have
// q = 0; the rest is the settling's adjustment to the piston and the ramp). With the geostatic
// start the same ice settles at up to 1.8 q_y and that step returns it to q_y. Near the piston's
// foot and the lip even the hydrostatic start settles above this q_y (docs/model.md).
TEST(FlowingGlacier, HydrostaticStartKeepsALowShearStrengthPlateauBelowYield) {
  nlohmann::json j = test::shipped_scene_json("flowing_2d.json");
  j["ice"]["initial_stress"] = "hydrostatic";
  j["drive"]["speed"] = 0.0;
  const double h = j["ice"]["thickness"].get<double>();
  const double q_y = 0.3 * j["ice"]["density"].get<double>() * j["gravity"]["g"].get<double>() * h;
  j["ice"]["shear_strength"] = q_y;
  const SceneConfig scene = scene_from_json(j);
  Simulation<2> sim(scene);
  sim.settle();
  sim.step();
  const auto& P = sim.particles();
  double q_max = 0.0;
  int checked = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (P.x[p][0] < h || P.x[p][0] > 3.0 * h) continue;
    q_max = std::max(q_max, von_mises_of<2>(P.tau[p]) / P.F_e[p].determinant());
    ++checked;
  }
  EXPECT_GT(checked, 100);
  EXPECT_LT(q_max, 0.8 * q_y);
}

// The gate past the lip records only ice that crosses it: the draped ice that starts past it is
// never recorded, so the passed length starts at 0 and grows with the ice's advance V_x·t.
TEST(FlowingGlacier, GateCountsOnlyIceThatCrossesIt) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json("flowing_2d.json"));
  ASSERT_GT(scene.gate_offset, 0.0);
  Simulation<2> sim(scene);
  sim.settle();
  sim.step();
  EXPECT_LT(sim.gate_passed_length(), 0.5 * scene.dx);
  EXPECT_EQ(sim.snapshot().gate_eps_v_p.size(), 0u);  // 1.6 cm of advance reaches no lattice point
  while (sim.time() < 10.0) sim.step();
  // The ice at the gate is on the ramp and moves at about V_x horizontally; a lattice column is
  // recorded whole, so the count steps by one particle spacing.
  EXPECT_NEAR(sim.gate_passed_length(), scene.drive_speed * sim.time(), 2.0 * scene.dx / scene.particles_per_cell_axis);
}

}  // namespace
}  // namespace crevasse
