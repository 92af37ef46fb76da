// The inflow boundary (drive.boundary "inflow"): the back layer of ice stays in place and ice
// enters through it at V_x, so the upstream ice is only as long as the scene asks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <vector>

#include "engine/error.hpp"
#include "engine/simulation.hpp"
#include "scene_builders.hpp"

namespace crevasse {
namespace {

// The shipped flowing glacier with an inflow boundary `upstream` H_i behind the lip.
SceneConfig inflow_scene(double thickness, double upstream, double friction = 0.1) {
  nlohmann::json j = test::shipped_scene_json("flowing_2d.json");
  j["ice"]["thickness"] = thickness;
  j["ice"]["upstream_length"] = upstream * thickness;
  j["ice"]["initial_stress"] = "hydrostatic";
  j["ice"]["shear_strength"] = 0.5 * 917.0 * 9.81 * thickness;
  j["ice"]["tensile_strength"] = 0.2 * 917.0 * 9.81 * thickness;
  j["bed"]["step_height"] = thickness;
  j["bed"]["step_length"] = thickness;
  j["bed"]["downstream_length"] = 3.0 * thickness;
  j["bed"]["friction"] = friction;
  j["drive"]["boundary"] = "inflow";
  j["run"]["gate_offset"] = 0.25 * thickness;
  j["run"]["gate_length"] = 20.0 * thickness;  // more than the slab holds: the inflow feeds it
  j["numerics"]["dx"] = thickness / 10.0;
  return scene_from_json(j);
}

// Mass enters at ρ_i H_i V_x per unit width: a column of H_i/h particles of mass ρ_i h² each time
// the drive has moved by one particle spacing h, so after time t the mass that entered is
// ρ_i H_i h floor(V_x t / h), within one column of ρ_i H_i V_x t. Nothing else makes or loses
// mass: what is in the domain plus what left is what was there plus what entered.
TEST(Inflow, MassEntersAtDensityTimesThicknessTimesSpeed) {
  const SceneConfig scene = inflow_scene(100.0, 2.0);
  Simulation<2> sim(scene);
  sim.settle();
  const double m0 = sim.total_mass();
  const double h = scene.dx / scene.particles_per_cell_axis;
  const double column = scene.density * scene.ice_thickness * h;
  while (sim.time() < 20.0) sim.step();
  const double expected = scene.density * scene.ice_thickness * scene.drive_speed * sim.time();
  EXPECT_GT(sim.inflow_mass(), expected - column);
  EXPECT_LE(sim.inflow_mass(), expected);
  EXPECT_NEAR(sim.inflow_mass() / column, std::floor(scene.drive_speed * sim.time() / h), 1e-9);
  EXPECT_NEAR(sim.total_mass() + sim.removed_mass(), m0 + sim.inflow_mass(), 1e-13 * m0);
}

// The back of the domain stays filled: the ice behind the lip keeps its length (it is fed, not
// consumed as behind a piston), and no gap opens between the entering ice and the ice ahead.
TEST(Inflow, TheUpstreamIceIsNeitherConsumedNorTorn) {
  const SceneConfig scene = inflow_scene(100.0, 2.0);
  Simulation<2> sim(scene);
  sim.settle();
  while (sim.time() < 30.0) sim.step();
  const auto& P = sim.particles();
  const double h = scene.dx / scene.particles_per_cell_axis;
  // Particles per lattice column of the plateau, in bands h wide from the back to the lip.
  const int bands = static_cast<int>(scene.step_top_x() / h);
  std::vector<int> count(bands, 0);
  double back = std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < P.size(); ++p) {
    back = std::min(back, P.x[p][0]);
    const int b = static_cast<int>(std::floor(P.x[p][0] / h));
    if (b >= 0 && b < bands) ++count[b];
  }
  EXPECT_LT(back, h);  // ice still reaches the back
  const int full = static_cast<int>(std::round(scene.ice_thickness / h));
  // Up to H_i before the lip: closer to it the ice surface already bends down over the step.
  const int checked = static_cast<int>((scene.step_top_x() - scene.ice_thickness) / h);
  for (int b = 1; b < checked; ++b) EXPECT_NEAR(count[b], full, 2) << "band at x = " << b * h << " m";
}

// Mass-weighted mean x of the ice that started with x in [x0, x1) (its gate-frame reference).
double mean_x_of_ice_started_in(const Simulation<2>& sim, double x0, double x1) {
  const auto& P = sim.particles();
  double mx = 0.0, m = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (P.x_ref[p][0] < x0 || P.x_ref[p][0] >= x1) continue;
    mx += P.mass[p] * P.x[p][0];
    m += P.mass[p];
  }
  return mx / m;
}

// The inflow feeds the plateau at V_x in thick ice, where the piston leaks (test_piston.cpp,
// DISABLED_StaysBehindTheIceAtEightHundredMetres): at H_i = 800 m the ice that started in the
// middle of the plateau advances at V_x within 1 % from 50 s to 100 s. Measured: 4.003 m/s;
// the piston of the same scene gives 3.95 m/s, and an inflow whose back layer was moved
// kinematically ahead of the grid's velocity gave 3.65 m/s (the entering ice crowded behind the
// ice it had been released into, without compressing it).
TEST(Inflow, HoldsTheDriveSpeedInThickIce) {
  const SceneConfig scene = inflow_scene(800.0, 2.0);
  Simulation<2> sim(scene);
  sim.settle();
  while (sim.time() < 50.0) sim.step();
  const double h = scene.ice_thickness;
  const double t0 = sim.time(), x0 = mean_x_of_ice_started_in(sim, 0.5 * h, h);
  while (sim.time() < 100.0) sim.step();
  const double speed = (mean_x_of_ice_started_in(sim, 0.5 * h, h) - x0) / (sim.time() - t0);
  EXPECT_NEAR(speed, scene.drive_speed, 0.01 * scene.drive_speed);
}

// The entering ice is the loaded glacier continued upstream: in the gate frame its reference
// positions fill every band h wide below x = 0 with one full column (no gap, no overlap), and
// while it is still in the held layer (x < 2.5 dx, where it moves at exactly V_x), away from the
// surface and the bed (depths 0.2–0.8 H_i), its vertical stress is the cryostatic
// σ_zz = −ρ_i g (s − z) of the start within 5 % of ρ_i g H_i. Ice entering unstressed, or a copy
// of the wrong band, would be off by tens of %. Past the layer the ice takes the plateau's own
// stress (the push against basal friction, the basal mode of docs/model.md), not checked here.
TEST(Inflow, EnteringIceContinuesTheGlacierUpstream) {
  const SceneConfig scene = inflow_scene(100.0, 2.0);
  Simulation<2> sim(scene);
  sim.settle();
  while (sim.time() < 30.0) sim.step();
  const auto& P = sim.particles();
  const double h = scene.dx / scene.particles_per_cell_axis;
  const int entered = static_cast<int>(std::floor(scene.drive_speed * sim.time() / h));
  ASSERT_GE(entered, 20);
  std::vector<int> count(entered, 0);
  const double rho_g = scene.density * scene.gravity;
  const double top = scene.step_height + scene.ice_thickness;
  double worst = 0.0;
  int stressed = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const double ref = P.x_ref[p][0];
    if (ref >= 0.0) continue;
    const int b = static_cast<int>(std::floor(-ref / h));
    ASSERT_LT(b, entered) << ref;
    ++count[b];
    const double depth = top - P.x[p][1];
    if (depth < 0.2 * scene.ice_thickness || depth > 0.8 * scene.ice_thickness) continue;
    if (P.x[p][0] >= 2.5 * scene.dx) continue;
    const double sigma_zz = P.tau[p](1, 1) / P.F_e[p].determinant();
    worst = std::max(worst, std::abs(sigma_zz + rho_g * depth) / (rho_g * scene.ice_thickness));
    ++stressed;
  }
  const int full = static_cast<int>(std::round(scene.ice_thickness / h));
  for (int b = 0; b < entered; ++b) EXPECT_EQ(count[b], full) << "band " << b;
  EXPECT_GT(stressed, 50);
  std::cout << "entering ice: sigma_zz within " << worst << " rho_i g H_i of the cryostatic state\n";
  EXPECT_LT(worst, 0.05);
}

TEST(Inflow, IsRefusedWithoutTheDriveOrABoundaryItKnows) {
  nlohmann::json j = test::shipped_scene_json("flowing_2d.json");
  j["drive"]["boundary"] = "sink";
  EXPECT_THROW(scene_from_json(j), InputError);
}

}  // namespace
}  // namespace crevasse
