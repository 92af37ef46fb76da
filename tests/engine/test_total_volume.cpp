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

enum class Average { none, increment, total, total_per_cell, total_per_cell_relaxed };

// The relaxation time of the relaxed per-cell average in these tests [s].
constexpr double kRelaxation = 0.05;

SceneConfig flowing_without_cap(Average a) {
  nlohmann::json j = test::shipped_scene_json("flowing_inflow_2d.json");
  // Plasticity with the shear yield only: a tensile strength no stress reaches, no softening.
  j["effects"] = {"gravity", "drive", "basal_friction", "plasticity", "outflow", "downstream_drive"};
  j["ice"]["tensile_strength"] = 1e9;
  j["run"]["gate_length"] = 0.0;
  j["run"]["end_time"] = 30.0;
  j["numerics"]["volumetric_averaging"] = a != Average::none;
  const bool per_cell = a == Average::total_per_cell || a == Average::total_per_cell_relaxed;
  if (a == Average::total || per_cell) j["numerics"]["average_total_volume"] = true;
  if (per_cell) j["numerics"]["average_per_cell"] = true;
  if (a == Average::total_per_cell_relaxed) j["numerics"]["average_relaxation_time"] = kRelaxation;
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
// dynamic stresses of the flow. The per-cell average relaxed over 0.05 s keeps to it (0.28 MPa);
// the per-cell mean alone does not (0.59 MPa).
TEST(TotalVolumeAverage, FlowingIceKeepsItsMeanStressWithinTheShearYieldBound) {
  const SceneConfig none = flowing_without_cap(Average::none);
  const double bound = none.shear_strength / std::sqrt(3.0);
  const double without = worst_tension(none);
  const double total = worst_tension(flowing_without_cap(Average::total));
  const double per_cell = worst_tension(flowing_without_cap(Average::total_per_cell));
  const double relaxed = worst_tension(flowing_without_cap(Average::total_per_cell_relaxed));
  EXPECT_GT(without, 2.0 * bound) << "the checkerboard this test guards against did not appear";
  EXPECT_LT(total, 1.2 * bound);
  EXPECT_LT(relaxed, 1.2 * bound);
  // The per-cell mean alone lets a mode through (docs/model.md, "Volume averaging and the time
  // step"): recorded, not asserted.
  RecordProperty("worst_tension_per_cell_pa", static_cast<int>(per_cell));
  RecordProperty("worst_tension_per_cell_relaxed_pa", static_cast<int>(relaxed));
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

RowVolumes row_checkerboard_after_one_step(bool total, bool per_cell = false) {
  const std::array<double, 3> lo{0.0, 0.0, 0.0}, hi{40.0, 20.0, 0.0};
  const std::array<double, 3> dlo{-10.0, -10.0, 0.0}, dhi{50.0, 30.0, 0.0};
  SceneConfig s = test::box_scene(2, lo, hi, dlo, dhi, {}, 1.0);
  s.volumetric_averaging = true;
  s.average_total_volume = total;
  s.average_per_cell = per_cell;
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
  const RowVolumes per_cell = row_checkerboard_after_one_step(true, true);
  EXPECT_LT(per_cell.contrast_ratio, 0.05);
  EXPECT_NEAR(per_cell.mean_after, kCompressed, 1e-6);
  EXPECT_GT(increment.contrast_ratio, 0.5);
  EXPECT_NEAR(increment.mean_after, kCompressed, 1e-6);
  RecordProperty("remaining_total_permille", static_cast<int>(1000 * total.contrast_ratio));
  RecordProperty("remaining_increment_permille", static_cast<int>(1000 * increment.contrast_ratio));
}

// An elastic column dropped onto a flat bed rings in its first mode (period 4H/c_p) with nothing
// to damp it but the transfers. The average must not add damping: each step it takes from every
// particle the part of its elastic volume the average does not reproduce, so an average that does
// not reproduce a smooth field damps the ringing by a fraction per step, and more per second the
// smaller the step. Measured: the top's oscillation keeps 79 % (CFL 0.25) and 75 % (CFL 0.5) of
// its first-period amplitude after 19 periods without any average (APIC's own loss), the same
// with the increment average and the per-cell average, but 2.5 % and 9.5 % with the stencil's
// whole-volume average: a damping per step, which is why that average's crevasse depths change
// with the time step (docs/model.md, "Volume averaging and the time step"). 10 % of the
// undamped amplitude is the tolerance: the per-cell average is within 2 %, and relaxed towards
// the stencil's over 0.05 s (a rate in seconds, not per step) within 3 %.
double top_amplitude_after_19_periods(Average a, double cfl) {
  constexpr double kH = 20.0, kW = 4.0;
  SceneConfig s = test::box_scene(2, {0.0, 0.0, 0.0}, {kW, kH, 0.0}, {0.0, -3.0, 0.0}, {kW, kH + 6.0, 0.0},
                                  {Effect::gravity, Effect::basal_friction, Effect::box_walls}, 1.0);
  s.bed_shape = BedShape::flat;
  s.flat_bed_z = 0.0;
  s.bed_friction = 0.0;
  s.wall_axes = {0};
  s.volumetric_averaging = a != Average::none;
  s.average_per_cell = a == Average::total_per_cell || a == Average::total_per_cell_relaxed;
  s.average_total_volume = a == Average::total || s.average_per_cell;
  if (a == Average::total_per_cell_relaxed) s.average_relaxation_time = kRelaxation;
  s.cfl = cfl;
  s = test::finish(s);
  Simulation<2> sim(s);
  const double period = 4.0 * kH / s.p_wave_speed();
  double lo = 1e300, hi = -1e300;
  while (sim.time() < 20.0 * period) {
    sim.step();
    if (sim.time() < 19.0 * period) continue;
    const auto& P = sim.particles();
    double z = 0.0;
    int n = 0;
    for (std::size_t p = 0; p < P.size(); ++p)
      if (P.x[p][1] > kH - 0.5) z += P.x[p][1], ++n;
    lo = std::min(lo, z / n);
    hi = std::max(hi, z / n);
  }
  return hi - lo;
}

TEST(TotalVolumeAverage, PerCellLeavesAColumnsRingingUndampedAtEveryTimeStep) {
  for (const double cfl : {0.25, 0.5}) {
    const double none = top_amplitude_after_19_periods(Average::none, cfl);
    const double per_cell = top_amplitude_after_19_periods(Average::total_per_cell, cfl);
    const double relaxed = top_amplitude_after_19_periods(Average::total_per_cell_relaxed, cfl);
    const double increment = top_amplitude_after_19_periods(Average::increment, cfl);
    const double stencil = top_amplitude_after_19_periods(Average::total, cfl);
    EXPECT_NEAR(per_cell / none, 1.0, 0.1) << "CFL " << cfl;
    EXPECT_NEAR(relaxed / none, 1.0, 0.1) << "CFL " << cfl;
    EXPECT_NEAR(increment / none, 1.0, 0.1) << "CFL " << cfl;
    RecordProperty(cfl < 0.3 ? "stencil_total_over_none_cfl025_permille" : "stencil_total_over_none_cfl05_permille",
                   static_cast<int>(1000 * stencil / none));
  }
}

TEST(TotalVolumeAverage, RelaxationNeedsThePerCellAverage) {
  nlohmann::json j = test::shipped_scene_json("flowing_weight_2d.json");
  j["numerics"]["average_relaxation_time"] = 0.05;
  try {
    scene_from_json(j);
    FAIL() << "accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("numerics.average_relaxation_time"), std::string::npos) << e.what();
  }
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
