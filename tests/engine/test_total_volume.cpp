// numerics.average_total_volume: the ΔJ-bar average taken over each particle's whole trial
// elastic volume ratio instead of the step's increment (docs/model.md, "Volume averaging on the
// flowing glacier").
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "engine/simulation.hpp"
#include "scene_builders.hpp"

namespace crevasse {
namespace {

enum class Average { none, increment, total };

SceneConfig flowing_without_cap(Average a) {
  nlohmann::json j = test::shipped_scene_json("flowing_inflow_2d.json");
  // Plasticity with the shear yield only: a tensile strength no stress reaches, no softening.
  j["effects"] = {"gravity", "drive", "basal_friction", "plasticity", "outflow", "downstream_drive"};
  j["ice"]["tensile_strength"] = 1e9;
  j["run"]["gate_length"] = 0.0;
  j["run"]["end_time"] = 30.0;
  j["numerics"]["volumetric_averaging"] = a != Average::none;
  if (a == Average::total) j["numerics"]["average_total_volume"] = true;
  return scene_from_json(j);
}

// The most tensile mean stress (−p) of any particle between 10 and 30 s.
double worst_tension(const SceneConfig& scene) {
  Simulation<2> sim(scene);
  sim.settle();
  double worst = 0.0;
  while (sim.time() < scene.end_time) {
    sim.step();
    if (sim.steps() % 50 != 0 || sim.time() < 10.0) continue;
    const auto snap = sim.snapshot();
    for (double p : snap.pressure_pa) worst = std::max(worst, -p);
  }
  return worst;
}

// In plane strain the shear yield bounds the half difference of the principal stresses by
// q_y/√3, so where one principal stress is not tensile (the free surface, or anywhere gravity
// compresses the ice) the mean stress cannot fall below −q_y/√3. Ice flowing over the step
// without a tensile cap must keep to that bound; a particle-row pressure checkerboard breaks it
// by a factor of several (measured without averaging: 3.7 MPa against 0.52 MPa at
// H_i = 200 m; 153 MPa on this scene with the increment average). The 20 % margin covers the
// dynamic stresses of the flow.
TEST(TotalVolumeAverage, FlowingIceKeepsItsMeanStressWithinTheShearYieldBound) {
  const SceneConfig none = flowing_without_cap(Average::none);
  const double bound = none.shear_strength / std::sqrt(3.0);
  const double without = worst_tension(none);
  const double total = worst_tension(flowing_without_cap(Average::total));
  EXPECT_GT(without, 2.0 * bound) << "the checkerboard this test guards against did not appear";
  EXPECT_LT(total, 1.2 * bound);
  RecordProperty("bound_pa", static_cast<int>(bound));
  RecordProperty("worst_tension_without_pa", static_cast<int>(without));
  RecordProperty("worst_tension_total_pa", static_cast<int>(total));
}

// A particle-row checkerboard of the elastic volume put in by hand, on top of a uniform
// compression, after one step: the total average removes the checkerboard and keeps the
// compression (a projection that flattened J towards 1 would remove both); the increment average
// keeps both (it only smooths what each step adds). Ice at rest, no gravity, so nothing else
// changes the volume within one step.
struct RowVolumes {
  double contrast_ratio;  // |J̄_a − J̄_b| after / before
  double mean_after;      // (J̄_a + J̄_b)/2 after
};
constexpr double kCompressed = 0.998;  // the uniform part of J

RowVolumes row_checkerboard_after_one_step(bool total) {
  const std::array<double, 3> lo{0.0, 0.0, 0.0}, hi{40.0, 20.0, 0.0};
  const std::array<double, 3> dlo{-10.0, -10.0, 0.0}, dhi{50.0, 30.0, 0.0};
  SceneConfig s = test::box_scene(2, lo, hi, dlo, dhi, {}, 1.0);
  s.volumetric_averaging = true;
  s.average_total_volume = total;
  Simulation<2> sim(test::finish(s));
  auto& P = sim.mutable_particles();
  const double h = 0.5;  // 2×2 particles per 1 m cell
  for (std::size_t p = 0; p < P.size(); ++p) {
    const int row = static_cast<int>(std::floor(P.x[p][1] / h));
    P.F_e[p](1, 1) = kCompressed + (row % 2 == 0 ? 0.001 : -0.001);
  }
  // Two neighbouring interior rows, away from the faces where the stencils are one-sided.
  const auto rows = [&] {
    double a = 0.0, b = 0.0;
    int na = 0, nb = 0;
    for (std::size_t p = 0; p < P.size(); ++p) {
      const double x = P.x[p][0], z = P.x[p][1];
      if (x < 10.0 || x > 30.0) continue;
      if (std::abs(z - 10.25) < 0.1) a += P.F_e[p].determinant(), ++na;
      if (std::abs(z - 10.75) < 0.1) b += P.F_e[p].determinant(), ++nb;
    }
    return std::array<double, 2>{a / na, b / nb};
  };
  const auto before = rows();
  sim.step();
  const auto after = rows();
  return {std::abs(after[0] - after[1]) / std::abs(before[0] - before[1]), 0.5 * (after[0] + after[1])};
}

TEST(TotalVolumeAverage, RemovesAParticleRowCheckerboardInOneStep) {
  const RowVolumes total = row_checkerboard_after_one_step(true);
  const RowVolumes increment = row_checkerboard_after_one_step(false);
  EXPECT_LT(total.contrast_ratio, 0.05);
  EXPECT_NEAR(total.mean_after, kCompressed, 1e-6);  // the compression is the average's to keep
  EXPECT_GT(increment.contrast_ratio, 0.5);
  EXPECT_NEAR(increment.mean_after, kCompressed, 1e-6);
  RecordProperty("remaining_total_permille", static_cast<int>(1000 * total.contrast_ratio));
  RecordProperty("remaining_increment_permille", static_cast<int>(1000 * increment.contrast_ratio));
}

TEST(TotalVolumeAverage, NeedsTheAverageOn) {
  nlohmann::json j = test::shipped_scene_json("flowing_inflow_2d.json");
  j["numerics"]["volumetric_averaging"] = false;
  j["numerics"]["average_total_volume"] = true;
  try {
    scene_from_json(j);
    FAIL() << "accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("numerics.average_total_volume"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace crevasse
