// Hard case, long run, labels `hard;slow`: the base hard case of
// ../test_hard_cases.cpp run for 10× its usual simulated time T_u. The drive is slowed to
// V_x/10 so that the ice makes the same journey (the piston stays on the plateau and the ice
// stays in the domain) over ten times as many steps: what accumulates over a long run
// (round-off in F_E, drift of the energy, particles creeping out) has ten times longer to show.
#include <gtest/gtest.h>

#include "../hard_case.hpp"
#include "../../scene_builders.hpp"

namespace crevasse {
namespace {

TEST(HardCaseLong, TenTimesTheUsualSimulatedTime) {
  test::SmallGlacier g;  // the base case: H_i = 100 m, dx = H_i/8, Π = 0.2, slope 1
  g.thickness = 100.0;
  g.cells_per_thickness = 8.0;
  SceneConfig s = test::small_glacier_scene(g);
  const double usual = s.drive_ramp_time + (s.step_length + s.ice_thickness) / s.drive_speed;
  g.drive_speed /= 10.0;
  s = test::small_glacier_scene(g);
  s.end_time = 10.0 * usual;
  const test::HardResult r = test::run_hard_case(s);
  test::expect_stable(s, r);
  // The run really is ten times as long: it reached 10 T_u with ice left, and dt can never
  // exceed cfl·dx/c_p, so covering 10 T_u takes at least that many steps (a run that ended
  // early, or skipped time with oversized steps, fails here).
  ASSERT_GT(r.final_particles, 0u) << "no ice left to check";
  EXPECT_GE(r.sim_time, 10.0 * usual * (1 - 1e-12));
  const double dt_max = s.cfl * s.dx / s.p_wave_speed();
  EXPECT_GE(static_cast<double>(r.steps), 10.0 * usual / dt_max * (1 - 1e-9));
}

}  // namespace
}  // namespace crevasse
