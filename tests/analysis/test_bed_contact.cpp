// The gap between the ice and its bed over the ramp (analysis/bed_contact.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "analysis/bed_contact.hpp"
#include "engine/simulation.hpp"

namespace crevasse::analysis {
namespace {

// A lattice of ice resting on a 45° ramp from x = 100 (z = 100) to x = 200 (z = 0), particle
// spacing 5 m, the lowest particle of each column half a spacing above the bed at its x.
ParticleSnapshot ice_on_ramp() {
  ParticleSnapshot s;
  s.dx_m = 10.0;
  s.particle_spacing_m = 5.0;
  s.step_top_x_m = 100.0;
  s.step_foot_x_m = 200.0;
  s.bed_profile = {{0.0, 100.0}, {100.0, 100.0}, {200.0, 0.0}, {400.0, 0.0}};
  for (double x = 2.5; x < 400.0; x += 5.0) {
    const double zb = x < 100.0 ? 100.0 : x < 200.0 ? 200.0 - x : 0.0;
    for (int k = 0; k < 10; ++k) {
      s.x.push_back(x);
      s.z.push_back(zb + 2.5 + 5.0 * k);
    }
  }
  return s;
}

TEST(BedContact, IceRestingOnTheRampHasNoGap) {
  const BedContact c = ramp_contact(ice_on_ramp());
  EXPECT_EQ(c.columns, 10u);
  EXPECT_EQ(c.empty_columns, 0u);
  EXPECT_NEAR(c.max_gap_m, 0.0, 1e-9);
}

TEST(BedContact, LiftedIceGivesItsGapAndWhere) {
  ParticleSnapshot s = ice_on_ramp();
  for (std::size_t p = 0; p < s.x.size(); ++p)
    if (s.x[p] > 150.0 && s.x[p] < 160.0) s.z[p] += 30.0;  // one column 30 m off the bed
  const BedContact c = ramp_contact(s);
  EXPECT_NEAR(c.max_gap_m, 30.0, 1e-9);
  EXPECT_NEAR(c.max_gap_x_m, 155.0, 1e-9);
}

TEST(BedContact, ColumnsWithoutIceAreCountedNotMeasured) {
  ParticleSnapshot s = ice_on_ramp();
  std::vector<double> x, z;
  for (std::size_t p = 0; p < s.x.size(); ++p)
    if (s.x[p] < 120.0 || s.x[p] > 140.0) {
      x.push_back(s.x[p]);
      z.push_back(s.z[p]);
    }
  s.x = x;
  s.z = z;
  const BedContact c = ramp_contact(s);
  EXPECT_EQ(c.empty_columns, 2u);
  EXPECT_NEAR(c.max_gap_m, 0.0, 1e-9);
}

TEST(BedContact, SnapshotWithoutBedIsRefused) {
  ParticleSnapshot s = ice_on_ramp();
  s.bed_profile.clear();
  EXPECT_THROW(ramp_contact(s), std::invalid_argument);
}

// The largest ice–ramp gap of a settled scene over its first `seconds`, sampled every 250 steps.
double largest_ramp_gap(const SceneConfig& scene, double seconds) {
  Simulation<2> sim(scene);
  sim.settle();
  double worst = 0.0;
  while (sim.time() < seconds) {
    sim.step();
    if (sim.steps() % 250 == 0) worst = std::max(worst, ramp_contact(sim.snapshot()).max_gap_m);
  }
  return worst;
}

// The flowing glacier stays on its 45° ramp: over its first 30 s (120 m of advance, more than
// the ramp is long) the bottom of the ice is never more than 1.5 cells above the ramp (measured:
// 12.6 m at most, where the ice bends over the lip). A glacier that cannot shear (q_y = 10 MPa,
// 11 ρ_i g H_i here) rides over the ramp as a rigid bridge instead: its gap grows as V_x·S·t,
// 37 m after 10 s and 45 m by 30 s (docs/model.md, "The flowing glacier").
TEST(BedContact, FlowingGlacierStaysInContactWithTheRamp) {
  std::ifstream f(std::string(CREVASSE_SOURCE_DIR) + "/studies/scenes/flowing_2d.json");
  const SceneConfig scene = scene_from_json(nlohmann::json::parse(f));
  ASSERT_EQ(scene.step_height, scene.step_length);  // S = 1
  EXPECT_LE(largest_ramp_gap(scene, 30.0), 1.5 * scene.dx);
}

// The same on the quick study's start (studies/scenes/flowing_weight_cell_2d.json: inflow, relaxed
// per-cell whole-volume average, gravity tilted by atan μ_b so that the ice's weight carries it) over its 45° ramp,
// H_i = 100 m, q_y = 0.5 ρ_i g H_i: over 40 s (160 m of advance) the bottom of the ice stays
// within 1.5 cells of the ramp.
TEST(BedContact, WeightDrivenGlacierWithTheWholeVolumeAverageStaysOnTheRamp) {
  std::ifstream f(std::string(CREVASSE_SOURCE_DIR) + "/studies/scenes/flowing_weight_cell_2d.json");
  const SceneConfig scene = scene_from_json(nlohmann::json::parse(f));
  ASSERT_EQ(scene.step_height, scene.step_length);  // S = 1
  ASSERT_TRUE(scene.average_total_volume);
  ASSERT_TRUE(scene.average_per_cell);
  ASSERT_NEAR(std::tan(scene.gravity_tilt_deg * M_PI / 180.0), scene.bed_friction, 1e-12);
  const double worst = largest_ramp_gap(scene, 40.0);
  RecordProperty("largest_gap_m", static_cast<int>(worst));
  EXPECT_LE(worst, 1.5 * scene.dx);
}

}  // namespace
}  // namespace crevasse::analysis
