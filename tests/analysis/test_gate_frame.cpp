// Measurement in the gate frame (docs/measurement.md, "Gate frame"): the damage each particle
// carried when it reached the top of the step, at its initial position. The current field of the
// same snapshot is deliberately different (rubble), so a test passes only if the right field is
// measured.
#include <gtest/gtest.h>

#include <stdexcept>

#include "analysis/crevasse_measure.hpp"
#include "synthetic_slab.hpp"

namespace crevasse::analysis {
namespace {

using test::make_slab;
using test::Notch;
using test::SlabSpec;

// A snapshot whose current particles are a fully damaged heap on the floor, and whose gate
// records are a slab [0, 1000] m × [100, 200] m with full-depth fractures at `notches`; the
// gate is at x = 1000 m and 800 m of ice has passed it.
ParticleSnapshot rubble_with_gate_records(const std::vector<Notch>& notches) {
  SlabSpec rubble;
  rubble.x_min_m = 1200.0;
  rubble.x_max_m = 1800.0;
  rubble.thickness_m = 30.0;
  ParticleSnapshot s = make_slab(rubble, {});
  for (double& e : s.eps_v_p) e = rubble.notch_eps_v_p;  // everything broken

  SlabSpec slab;
  slab.x_min_m = 0.0;
  slab.x_max_m = 1000.0;
  slab.thickness_m = 100.0;
  slab.base_z = [](double) { return 100.0; };
  slab.noise_over_spacing = 0.2;
  const ParticleSnapshot ref = make_slab(slab, notches);
  s.gate_x_m = 1000.0;
  s.gate_passed_length_m = 800.0;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    if (ref.x[i] < 200.0) continue;  // not through the gate yet
    s.gate_x_ref.push_back(ref.x[i]);
    s.gate_z_ref.push_back(ref.z[i]);
    s.gate_eps_v_p.push_back(ref.eps_v_p[i]);
  }
  s.ice_thickness_m = 100.0;
  s.step_top_x_m = 1000.0;
  s.step_foot_x_m = 1100.0;
  return s;
}

TEST(GateFrame, AutoMeasuresTheRecordedFractures) {
  const std::vector<Notch> notches = {
      {.x_m = 400.0, .depth_m = 100.0}, {.x_m = 520.0, .depth_m = 100.0},
      {.x_m = 640.0, .depth_m = 60.0},  {.x_m = 760.0, .depth_m = 100.0}};
  const ParticleSnapshot s = rubble_with_gate_records(notches);
  const CrevasseMeasurement m = measure_crevasses(s);  // frame "auto"
  EXPECT_EQ(m.settings.frame, "gate");
  // Default window in the gate frame: [gate − passed + H/2, gate − H/2] = [250, 950].
  EXPECT_DOUBLE_EQ(m.settings.window_min_x_m, 250.0);
  EXPECT_DOUBLE_EQ(m.settings.window_max_x_m, 950.0);
  EXPECT_FALSE(m.flags.fragmented);
  ASSERT_EQ(m.crevasses.size(), notches.size());
  for (std::size_t k = 0; k < notches.size(); ++k) {
    // One cell: the notch is one particle column, positions carry ±0.2 spacing of noise.
    EXPECT_NEAR(m.crevasses[k].x_m, notches[k].x_m, s.dx_m) << k;
    EXPECT_NEAR(m.crevasses[k].depth_m, notches[k].depth_m, s.dx_m) << k;
  }
  ASSERT_TRUE(m.spacing_m.has_value());
  EXPECT_NEAR(m.spacing_m->median, 120.0, s.dx_m);
}

TEST(GateFrame, FinalFrameMeasuresTheCurrentParticles) {
  const ParticleSnapshot s = rubble_with_gate_records({{.x_m = 500.0, .depth_m = 100.0}});
  MeasureSettings settings;
  settings.frame = "final";
  const CrevasseMeasurement m = measure_crevasses(s, settings);
  EXPECT_EQ(m.settings.frame, "final");
  EXPECT_TRUE(m.flags.fragmented);  // the heap is all damaged
}

TEST(GateFrame, GateWithoutRecordsAndUnknownFramesAreRefused) {
  SlabSpec slab;
  const ParticleSnapshot plain = make_slab(slab, {});
  MeasureSettings settings;
  settings.frame = "gate";
  EXPECT_THROW(measure_crevasses(plain, settings), std::invalid_argument);
  settings.frame = "initial";
  EXPECT_THROW(measure_crevasses(plain, settings), std::invalid_argument);
  // "auto" without records falls back to the final frame.
  settings.frame = "auto";
  EXPECT_EQ(measure_crevasses(plain, settings).settings.frame, "final");
}

TEST(GateFrame, SnapshotOfTheRecordsCarriesTheirPositionsAndDamage) {
  const ParticleSnapshot s = rubble_with_gate_records({{.x_m = 500.0, .depth_m = 100.0}});
  const ParticleSnapshot g = gate_frame_snapshot(s);
  ASSERT_EQ(g.size(), s.gate_eps_v_p.size());
  EXPECT_EQ(g.x, s.gate_x_ref);
  EXPECT_EQ(g.z, s.gate_z_ref);
  EXPECT_EQ(g.eps_v_p, s.gate_eps_v_p);
  EXPECT_EQ(g.vx.size(), g.size());
  EXPECT_DOUBLE_EQ(g.front_x(), 1000.0);  // the gate
  EXPECT_THROW(gate_frame_snapshot(make_slab(SlabSpec{}, {})), std::invalid_argument);
}

}  // namespace
}  // namespace crevasse::analysis
