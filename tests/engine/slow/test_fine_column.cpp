// Finer versions of the elastic column (tests/engine/test_elastic_column.cpp): the same 20 m
// column, unstressed start, base stress from the time-averaged linear fit of σ_zz(z) over
// whole first-mode periods (boundary cells left out), at dx = 0.5 m and 0.25 m in 2D.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "../scene_builders.hpp"
#include "engine/simulation.hpp"

namespace crevasse {
namespace {

constexpr double kHeight = 20.0, kWidth = 4.0;

double base_stress_error(double dx) {
  SceneConfig s = test::box_scene(2, {0, 0, 0}, {kWidth, kHeight, 0}, {0, -3 * dx, 0},
                                  {kWidth, kHeight + 6 * dx, 0},
                                  {Effect::gravity, Effect::basal_friction, Effect::box_walls}, dx);
  s.bed_shape = BedShape::flat;
  s.bed_friction = 0.0;
  s.wall_axes = {0};
  s = test::finish(s);
  Simulation<2> sim(s);
  const double t_end = 6 * 4.0 * kHeight / s.p_wave_speed();
  const double weight = sim.total_mass() * test::kG / kWidth;
  const double a = test::time_averaged_stress_line(sim, t_end, dx, kHeight)[0];
  const double rel = std::abs(-a - weight) / weight;
  std::cout << "dx " << dx << " m: base stress rel. error " << rel << "\n";
  return rel;
}

// 2%: the acceptance tolerance of the fast test (measured 0.8% at dx = 1 m).
TEST(ElasticColumnFine, BaseStressEqualsWeightAtFinerGrids) {
  EXPECT_LT(base_stress_error(0.5), 0.02);
  EXPECT_LT(base_stress_error(0.25), 0.02);
}

}  // namespace
}  // namespace crevasse
