// The measurement gate at the top of the step (docs/measurement.md, "Gate frame"): each particle
// is recorded once, when it first reaches x ≥ gate_x, with its initial position and the ε_v^p it
// carries then; records outlive the outflow; run.gate_length stops the run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <vector>

#include "engine/error.hpp"
#include "engine/run.hpp"
#include "engine/simulation.hpp"
#include "scene_builders.hpp"

namespace crevasse {
namespace {

// The particles of the slab's front column (within one particle spacing of the gate).
std::vector<std::size_t> front_column(const Simulation<2>& sim) {
  const auto& P = sim.particles();
  const double h = sim.scene().dx / sim.scene().particles_per_cell_axis;
  std::vector<std::size_t> out;
  for (std::size_t p = 0; p < P.size(); ++p)
    if (P.x[p][0] > sim.scene().gate_x() - h) out.push_back(p);
  return out;
}

TEST(Gate, RecordsEachParticleOnceWithTheDamageItCarriedAtTheGate) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json());
  ASSERT_TRUE(scene.records_gate());
  Simulation<2> sim(scene);
  sim.settle();
  ASSERT_TRUE(sim.records_gate());
  EXPECT_EQ(sim.snapshot().gate_eps_v_p.size(), 0u);  // nothing has reached the gate yet
  EXPECT_EQ(sim.gate_passed_length(), 0.0);

  // Push the front column 1 m past the gate with a known ε_v^p, remembering where it started.
  auto& P = sim.mutable_particles();
  const std::vector<std::size_t> column = front_column(sim);
  ASSERT_EQ(column.size(), static_cast<std::size_t>(scene.ice_thickness / 5.0));  // 20 particles
  std::vector<std::array<double, 2>> start;
  for (std::size_t p : column) {
    start.push_back({P.x[p][0], P.x[p][1]});
    P.x[p][0] = scene.gate_x() + 1.0;
    P.eps_v_p[p] = 0.3;
  }
  sim.step();
  ParticleSnapshot s = sim.snapshot();
  ASSERT_EQ(s.gate_eps_v_p.size(), column.size());
  EXPECT_EQ(s.gate_x_m, scene.gate_x());
  for (std::size_t k = 0; k < column.size(); ++k) {
    // One step may open the moved particles a little more; 1e-3 is 300× the softening scale
    // of one step at this strain rate and far below the 0.3 written.
    EXPECT_NEAR(s.gate_eps_v_p[k], 0.3, 1e-3);
  }
  // Initial positions: the seeding lattice (the front column's centres at gate − h/2), not
  // where settling left them (a few cm away); stored as float, 1e-4 m at x ~ 500 m.
  const double h = scene.dx / scene.particles_per_cell_axis;
  for (double x : s.gate_x_ref) EXPECT_NEAR(x, scene.gate_x() - 0.5 * h, 1e-4);
  for (std::size_t k = 0; k < start.size(); ++k) EXPECT_NEAR(s.gate_x_ref[k], start[k][0], 0.1);
  // Passed length: one column of particles = one particle spacing of slab (h·H_i / H_i).
  EXPECT_NEAR(sim.gate_passed_length(), h, 1e-9 * h);
  EXPECT_NEAR(s.gate_passed_length_m, h, 1e-9 * h);

  // Later damage does not change a record, and a particle is recorded only once. (A step may
  // reorder the particles, so the recorded ones are found again by their records.)
  for (std::size_t p = 0; p < P.size(); ++p)
    if (P.gate_eps[p] >= 0.0f) P.eps_v_p[p] = 0.9;
  sim.step();
  s = sim.snapshot();
  EXPECT_EQ(s.gate_eps_v_p.size(), column.size());
  for (double e : s.gate_eps_v_p) EXPECT_NEAR(e, 0.3, 1e-3);
  EXPECT_NEAR(sim.gate_passed_length(), h, 1e-9 * h);
}

TEST(Gate, RecordsOutliveTheOutflow) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json());
  Simulation<2> sim(scene);
  sim.settle();
  auto& P = sim.mutable_particles();
  const std::vector<std::size_t> column = front_column(sim);
  for (std::size_t p : column) {
    P.x[p][0] = scene.gate_x() + 1.0;
    P.eps_v_p[p] = 0.3;
  }
  sim.step();
  ASSERT_EQ(sim.snapshot().gate_eps_v_p.size(), column.size());
  // Now throw the recorded column into the outflow zone at the end of the floor.
  const double x_end = scene.upstream_length + scene.step_length + scene.downstream_length;
  const std::size_t n_before = P.size();
  std::size_t thrown = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (P.gate_eps[p] < 0.0f) continue;  // a step may reorder particles: find them again
    P.x[p][0] = x_end - scene.dx;
    ++thrown;
  }
  ASSERT_EQ(thrown, column.size());
  sim.step();
  EXPECT_EQ(sim.particles().size(), n_before - column.size());  // removed
  const ParticleSnapshot s = sim.snapshot();
  ASSERT_EQ(s.gate_eps_v_p.size(), column.size());  // still recorded
  for (double e : s.gate_eps_v_p) EXPECT_NEAR(e, 0.3, 1e-3);
}

TEST(Gate, GateLengthStopsTheRun) {
  nlohmann::json j = test::shipped_scene_json();
  j["run"] = {{"gate_length", 30.0}, {"end_time", 200.0}};
  j["output"]["vtu_interval"] = 0.0;
  const SceneConfig scene = scene_from_json(j);
  const RunSummary r = run_scene(scene);
  EXPECT_EQ(r.stop_reason, "gate_length");
  // Checked every step; one step passes far less than one particle column (5 m) at 4 m/s, but
  // a column reaches the gate at once, so the overshoot is at most about one column.
  EXPECT_GE(r.final_snapshot.gate_passed_length_m, 30.0);
  EXPECT_LT(r.final_snapshot.gate_passed_length_m, 30.0 + 2.0 * 5.0);
  EXPECT_LT(r.sim_time_s, 200.0);
}

// The stall rule alone: no verdict during the ramp; steady passing never stalls; less than
// one cell of growth for longer than the window does, and any cell of growth restarts it.
TEST(Gate, StallWatchNeedsAWindowWithoutACellOfGrowth) {
  GateStallWatch w;
  w.window_s = 50.0;
  w.min_growth_m = 10.0;
  w.ramp_s = 20.0;
  EXPECT_FALSE(w.stalled(0.0, 0.0));
  EXPECT_FALSE(w.stalled(19.0, 0.0));  // ramp
  // Passing at 0.5 m/s: the window restarts at every 10 m (the last at t = 480 s, 230 m).
  for (double t = 20.0; t < 500.0; t += 1.0) ASSERT_FALSE(w.stalled(t, 0.5 * (t - 20.0))) << t;
  // Then it stops short of 240 m: 9.9 m is less than a cell, so the window runs from 480 s.
  EXPECT_FALSE(w.stalled(500.0, 239.9));
  EXPECT_FALSE(w.stalled(529.0, 239.9));
  EXPECT_TRUE(w.stalled(531.0, 239.9));
  // One cell more restarts the window.
  EXPECT_FALSE(w.stalled(532.0, 240.0));
  EXPECT_FALSE(w.stalled(580.0, 245.0));
  EXPECT_TRUE(w.stalled(582.5, 245.0));
}

// A run whose ice stops reaching the gate stops. Here a fixed grip (a velocity box at rest
// across the whole height at the top of the step) holds the ice back, so nothing passes after
// the ramp: without the stall rule the run would go on to its end time (the guard of 400 s; at
// H_i = 400 m, V_x = 2 m/s a study case ran into its 30 min wall-time limit this way, with the
// last block left on the plateau); with it, it stops as "gate_stalled" one window
// (2·H_i/V_x = 25 s) after the passing stopped and keeps what passed for the measurement.
TEST(Gate, ARunWhoseIceStopsReachingTheGateStops) {
  test::SmallGlacier g;
  g.end_time = 400.0;
  SceneConfig scene = test::small_glacier_scene(g);
  scene.gate_length = 0.5 * scene.upstream_length;
  scene.effects.push_back(Effect::velocity_boundaries);
  VelocityBox hold;
  hold.min = {scene.gate_x() - 2.0 * scene.dx, -1e4, -1e4};
  hold.max = {scene.gate_x() + 2.0 * scene.dx, 1e4, 1e4};
  hold.velocity = {0.0, 0.0, 0.0};
  scene.velocity_boxes = {hold};
  scene = test::finish(scene);
  const RunSummary r = run_scene(scene);
  EXPECT_EQ(r.stop_reason, "gate_stalled");
  const double window = 2.0 * scene.ice_thickness / scene.drive_speed;
  EXPECT_GT(r.sim_time_s, scene.drive_ramp_time + window);
  EXPECT_LT(r.sim_time_s, scene.drive_ramp_time + 2.0 * window);
  EXPECT_LT(r.final_snapshot.gate_passed_length_m, scene.dx);
}

// The wall-time limit ends a run with one readable line: the limit as given, the simulated
// time and step reached, and how far the stop rules had got.
TEST(Gate, WallTimeLimitSaysWhereTheRunWas) {
  test::SmallGlacier g;
  SceneConfig scene = test::small_glacier_scene(g);
  scene.gate_length = 0.5 * scene.upstream_length;
  scene.wall_time_limit = 0.05;
  scene = test::finish(scene);
  try {
    run_scene(scene);
    FAIL() << "the run ended before its 0.05 s wall-time limit";
  } catch (const SimulationError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("time limit: run.wall_time_limit = 0.05 s reached at t = ", 0), 0u) << m;
    EXPECT_NE(m.find("% done)"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

TEST(Gate, GateLengthIsRefusedWhereThereIsNoGate) {
  nlohmann::json j = test::shipped_scene_json();
  j["run"]["gate_length"] = 600.0;  // more than the 500 m slab
  try {
    scene_from_json(j);
    FAIL() << "gate_length beyond the slab was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("run.gate_length"), std::string::npos) << e.what();
  }
  j = test::shipped_scene_json();
  j["run"]["gate_length"] = 100.0;
  j["effects"] = {"gravity", "drive", "basal_friction", "outflow"};  // elastic: no damage to record
  try {
    scene_from_json(j);
    FAIL() << "gate_length without plasticity was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("run.gate_length"), std::string::npos) << e.what();
  }
}

// The piston layer (the drive), applied by the update sweep to each particle as it is written:
// at the end of every step each driven particle sits at its initial x plus the drive's
// displacement at the step's end time, moving at the drive speed. Evaluated at the start of the
// step instead, the layer lags one step behind (by V_x·dt, ~1 cm here) and this fails.
TEST(Piston, LayerSitsAtTheDrivePositionAtTheEndOfEveryStep) {
  const SceneConfig scene = scene_from_json(test::shipped_scene_json());
  Simulation<2> sim(scene);
  sim.settle();
  const auto& P = sim.particles();
  std::size_t driven = 0;
  for (int i = 0; i < 40; ++i) {
    sim.step();
    const double shift = scene.drive_position(sim.time());
    const double v = scene.drive_velocity(sim.time());
    ASSERT_GT(shift, 0.0);
    driven = 0;
    for (std::size_t p = 0; p < P.size(); ++p) {
      if (std::isnan(P.drive_x0[p])) continue;
      ++driven;
      ASSERT_EQ(P.x[p][0], P.drive_x0[p] + shift) << "step " << i << ", particle " << p;
      ASSERT_EQ(P.v[p][0], v);
    }
  }
  EXPECT_GT(driven, 0u);
}

}  // namespace
}  // namespace crevasse
