// Crevasse measurement on synthetic slabs whose crevasses are known exactly (docs/measurement.md).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "analysis/crevasse_measure.hpp"
#include "analysis/measurement_io.hpp"
#include "synthetic_slab.hpp"

namespace crevasse::analysis {
namespace {

using test::make_slab;
using test::Notch;
using test::SlabSpec;

// Notches every `spacing` metres from x_min + H_i to x_max − H_i (inside the default window),
// with depths cycling through `depths`.
std::vector<Notch> notch_train(const SlabSpec& spec, double spacing, std::vector<double> depths) {
  std::vector<Notch> notches;
  std::size_t k = 0;
  for (double x = spec.x_min_m + spec.thickness_m + 0.3 * spec.dx_m;
       x <= spec.x_max_m - spec.thickness_m; x += spacing, ++k) {
    notches.push_back({.x_m = x, .depth_m = depths[k % depths.size()]});
  }
  return notches;
}

// Every number in a JSON document is finite (nlohmann writes NaN as null, so also no nulls
// outside the documented optional statistics).
void expect_all_finite(const nlohmann::json& j) {
  if (j.is_number()) {
    EXPECT_TRUE(std::isfinite(j.get<double>()));
  } else if (j.is_structured()) {
    for (const auto& v : j) expect_all_finite(v);
  }
}

void expect_measurement_finite(const CrevasseMeasurement& m) {
  expect_all_finite(measurement_summary_json(m));
  for (double z : m.surface.z_m) EXPECT_TRUE(std::isfinite(z));
}

void expect_matches(const CrevasseMeasurement& m, const std::vector<Notch>& notches, double tol) {
  ASSERT_EQ(m.crevasses.size(), notches.size());
  for (std::size_t i = 0; i < notches.size(); ++i) {
    EXPECT_NEAR(m.crevasses[i].x_m, notches[i].x_m, tol) << "crevasse " << i;
    EXPECT_NEAR(m.crevasses[i].depth_m, notches[i].depth_m, tol) << "crevasse " << i;
  }
}

struct SpacingCase {
  double spacing_m;
  double thickness_m;
};

class MeasureSpacing : public ::testing::TestWithParam<SpacingCase> {};

TEST_P(MeasureSpacing, RecoversPositionsDepthsAndSpacingUnderNoise) {
  const auto [spacing, thickness] = GetParam();
  SlabSpec spec{.thickness_m = thickness, .x_max_m = 2500.0, .noise_over_spacing = 0.2};
  // Depths are whole particle layers (multiples of dx/2) so the truth is exact on the lattice.
  const auto notches = notch_train(spec, spacing, {0.3 * thickness, 0.5 * thickness, 40.0});
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches));

  // One cell: the lattice puts a notch up to half a spacing from its nominal x, the ±20% noise
  // moves particles by up to 0.2 spacings, and the surface is resolved on dx-bins.
  const double tol = spec.dx_m;
  expect_matches(m, notches, tol);
  EXPECT_EQ(m.dropped_spacing_count, 0u);
  ASSERT_TRUE(m.flags.has_spacing);
  ASSERT_TRUE(m.spacing_m.has_value());
  EXPECT_NEAR(m.spacing_m->median, spacing, tol);
  EXPECT_NEAR(m.spacing_over_h->median, spacing / thickness, tol / thickness);
  EXPECT_EQ(m.spacings_m.size(), notches.size() - 1);
  EXPECT_FALSE(m.flags.fragmented);
  EXPECT_FALSE(m.flags.no_crevasse);
  expect_measurement_finite(m);
}

INSTANTIATE_TEST_SUITE_P(Synthetic, MeasureSpacing,
                         ::testing::Values(SpacingCase{40.0, 100.0}, SpacingCase{60.0, 200.0},
                                           SpacingCase{100.0, 300.0}, SpacingCase{60.0, 100.0}));

TEST(MeasureQuartiles, FollowLinearInterpolationBetweenOrderStatistics) {
  SlabSpec spec{.thickness_m = 100.0, .x_max_m = 1000.0};
  // Spacings 40, 60, 80, 100 m: type-7 quartiles 55, 70, 85 m.
  std::vector<Notch> notches;
  double x = 150.0;
  for (double s : {40.0, 60.0, 80.0, 100.0, 0.0}) {
    notches.push_back({.x_m = x + 1.0, .depth_m = 30.0});
    x += s;
  }
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches));
  ASSERT_TRUE(m.spacing_m.has_value());
  // Exact lattice, no noise: positions are column centres, identical offsets cancel.
  EXPECT_NEAR(m.spacing_m->q25, 55.0, 1e-9);
  EXPECT_NEAR(m.spacing_m->median, 70.0, 1e-9);
  EXPECT_NEAR(m.spacing_m->q75, 85.0, 1e-9);
  EXPECT_NEAR(m.depth_m->median, 30.0, 1e-9);
  EXPECT_NEAR(m.depth_over_h->median, 0.3, 1e-9);
}

TEST(MeasureIntact, SlabWithoutDamageHasNoCrevasse) {
  const CrevasseMeasurement m = measure_crevasses(make_slab({.noise_over_spacing = 0.2}, {}));
  EXPECT_TRUE(m.crevasses.empty());
  EXPECT_TRUE(m.flags.no_crevasse);
  EXPECT_FALSE(m.flags.has_spacing);
  EXPECT_FALSE(m.spacing_m.has_value());
  EXPECT_FALSE(m.depth_m.has_value());
  EXPECT_FALSE(m.flags.fragmented);
  EXPECT_FALSE(m.flags.empty_window);
  EXPECT_EQ(m.cluster_count, 0u);
  expect_measurement_finite(m);
}

TEST(MeasureBuried, DamageThatDoesNotReachTheSurfaceIsNotACrevasse) {
  SlabSpec spec;
  // Buried 30 m below the surface: beyond the 1.5·dx = 15 m reach.
  const std::vector<Notch> notches = {
      {.x_m = 500.0, .depth_m = 80.0, .width_m = 20.0, .top_gap_m = 30.0},
      {.x_m = 900.0, .depth_m = 50.0}};
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches));
  EXPECT_EQ(m.cluster_count, 2u);
  ASSERT_EQ(m.crevasses.size(), 1u);
  // One cell: lattice placement of the notch column.
  EXPECT_NEAR(m.crevasses[0].x_m, 900.0, spec.dx_m);
  EXPECT_NEAR(m.crevasses[0].depth_m, 50.0, spec.dx_m);
}

// An opened fracture is a line of damage broken by intact particles and empty gaps. The default
// link (2.1 particle spacings) bridges one particle, so two broken columns, 150 and 90 m deep,
// are measured to their bottoms within one cell; a link of 1.5 spacings (lattice neighbours
// only) stops each at its first break, above the 3·dx depth floor, and sees no crevasse.
TEST(MeasureBrokenLine, AFractureBrokenByOneParticleIsMeasuredToItsBottom) {
  SlabSpec spec;
  spec.thickness_m = 200.0;
  ParticleSnapshot s = make_slab(spec, {{.x_m = 600.0, .depth_m = 150.0}, {.x_m = 1200.0, .depth_m = 90.0}});
  const double h = test::spacing_of(spec);
  std::vector<std::size_t> keep;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const int row = static_cast<int>(std::floor((spec.thickness_m - s.z[i]) / h));  // 0 at the surface
    const bool in_line = s.eps_v_p[i] > 0.0;
    if (in_line && row % 4 == 2) s.eps_v_p[i] = 0.0;  // an intact particle every 20 m
    if (!(in_line && row % 8 == 4)) keep.push_back(i);  // and one gone between them every 40 m
  }
  ParticleSnapshot broken = s;
  for (auto* v : {&broken.x, &broken.y, &broken.z, &broken.vx, &broken.vy, &broken.vz, &broken.eps_v_p,
                  &broken.pressure_pa, &broken.von_mises_pa, &broken.sigma_zz_pa, &broken.volume_m3}) {
    const std::vector<double> all = *v;
    if (all.empty()) continue;
    v->clear();
    for (std::size_t i : keep) v->push_back(all[i]);
  }
  ASSERT_LT(broken.size(), s.size());
  const CrevasseMeasurement m = measure_crevasses(broken);
  ASSERT_EQ(m.crevasses.size(), 2u);
  EXPECT_NEAR(m.crevasses[0].x_m, 600.0, spec.dx_m);
  EXPECT_NEAR(m.crevasses[0].depth_m, 150.0, spec.dx_m);
  EXPECT_NEAR(m.crevasses[1].x_m, 1200.0, spec.dx_m);
  EXPECT_NEAR(m.crevasses[1].depth_m, 90.0, spec.dx_m);

  MeasureSettings neighbours_only;
  neighbours_only.link_distance_over_spacing = 1.5;
  const CrevasseMeasurement short_link = measure_crevasses(broken, neighbours_only);
  EXPECT_EQ(short_link.crevasses.size(), 0u);
  EXPECT_EQ(m.cluster_count, 2u);
  EXPECT_EQ(short_link.cluster_count, 12u + 7u) << "one cluster per unbroken strand";
}

// A lens one or two particle rows under an intact surface row (the strong-ice case of the
// flowing glacier's hand count, docs/measurement.md) and a notch 20 m deep both reach the
// surface but are shallower than the 3·dx = 30 m depth floor: counted as shallow, not as
// crevasses; the 50 m notch is measured. With the floor at 0 all three are crevasses.
TEST(MeasureDepthFloor, FeaturesShallowerThanThreeCellsAreNotCrevasses) {
  SlabSpec spec;
  const std::vector<Notch> notches = {
      {.x_m = 300.0, .depth_m = 15.0, .width_m = 10.0, .top_gap_m = 5.0},
      {.x_m = 600.0, .depth_m = 20.0},
      {.x_m = 900.0, .depth_m = 50.0}};
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches));
  EXPECT_EQ(m.cluster_count, 3u);
  EXPECT_EQ(m.shallow_count, 2u);
  ASSERT_EQ(m.crevasses.size(), 1u);
  EXPECT_NEAR(m.crevasses[0].x_m, 900.0, spec.dx_m);
  EXPECT_NEAR(m.crevasses[0].depth_m, 50.0, spacing_of(spec));
  EXPECT_FALSE(m.flags.has_spacing);

  MeasureSettings all;
  all.min_depth_over_dx = 0.0;
  const CrevasseMeasurement every = measure_crevasses(make_slab(spec, notches), all);
  EXPECT_EQ(every.shallow_count, 0u);
  ASSERT_EQ(every.crevasses.size(), 3u);
  EXPECT_NEAR(every.crevasses[0].depth_m, 15.0, spacing_of(spec));
  EXPECT_NEAR(every.crevasses[1].depth_m, 20.0, spacing_of(spec));
  EXPECT_EQ(every.spacings_m.size(), 2u);
}

// Four notches of which two stand 20 m apart, closer than the floor 3·dx = 30 m.
std::vector<Notch> close_pair_notches() {
  return {{.x_m = 300.0, .depth_m = 30.0},
          {.x_m = 400.0, .depth_m = 30.0},
          {.x_m = 420.0, .depth_m = 50.0},
          {.x_m = 520.0, .depth_m = 30.0}};
}

TEST(MeasureFloor, NotchesCloserThanTheFloorCountAsOne) {
  SlabSpec spec;
  // 20 m < 3·dx = 30 m apart: one feature at this resolution, keeping the deeper one.
  const std::vector<Notch> notches = close_pair_notches();
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches));
  ASSERT_EQ(m.crevasses.size(), 3u);
  EXPECT_EQ(m.dropped_spacing_count, 1u);
  EXPECT_EQ(m.spacings_m.size(), 2u);
  EXPECT_EQ(m.crevasses[1].merged_count, 2u);
  // One cell: lattice placement.
  EXPECT_NEAR(m.crevasses[1].x_m, 420.0, spec.dx_m);
  EXPECT_NEAR(m.crevasses[1].depth_m, 50.0, spec.dx_m);
  // The merged width spans both notches: 20 m apart plus one column.
  EXPECT_NEAR(m.crevasses[1].width_m, 25.0, spec.dx_m);
  for (double s : m.spacings_m) EXPECT_GE(s, m.settings.resolution_floor_m);
}

// The source study's rule on the same field: nothing merged; both notches 20 m apart stay, with
// their own depths, and only the 20 m spacing between them is dropped and counted. The
// spacings are then 100, 100 m (300→400, 420→520) instead of 120, 100 m.
TEST(MeasureFloor, SourceRuleKeepsBothAndDropsOnlyTheSpacing) {
  SlabSpec spec;
  const std::vector<Notch> notches = close_pair_notches();
  MeasureSettings source;
  source.spacing_rule = "drop";
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches), source);
  ASSERT_EQ(m.crevasses.size(), 4u);
  EXPECT_EQ(m.dropped_spacing_count, 1u);
  ASSERT_EQ(m.spacings_m.size(), 2u);
  for (const Crevasse& c : m.crevasses) EXPECT_EQ(c.merged_count, 1u);
  EXPECT_NEAR(m.crevasses[1].depth_m, 30.0, spec.dx_m);
  EXPECT_NEAR(m.crevasses[2].depth_m, 50.0, spec.dx_m);
  EXPECT_FALSE(m.crevasses[1].spacing_to_next_m.has_value());
  EXPECT_NEAR(m.spacings_m[0], 100.0, spec.dx_m);
  EXPECT_NEAR(m.spacings_m[1], 100.0, spec.dx_m);
  EXPECT_EQ(m.settings.spacing_rule, "drop");
  // The median depth sees four crevasses: 30, 30, 30, 50 m.
  ASSERT_TRUE(m.depth_m.has_value());
  EXPECT_NEAR(m.depth_m->median, 30.0, spec.dx_m);
  MeasureSettings bad;
  bad.spacing_rule = "keep";
  EXPECT_THROW(measure_crevasses(make_slab(spec, notches), bad), std::invalid_argument);
}

// A notched slab as after a run over a step whose top is at x = 100 m, the ice that started
// upstream of it having got to x = 900 m; the ice past that lay past the step from the start.
ParticleSnapshot slab_past_a_step(const SlabSpec& spec, const std::vector<Notch>& notches) {
  ParticleSnapshot s = make_slab(spec, notches);
  s.step_top_x_m = 100.0;
  s.upstream_ice_front_x_m = 900.0;
  return s;
}

// The "passed" frame measures the ice that came over the step during the run: from half an H_i
// past the top of the step to half an H_i behind the front of the ice that started upstream of
// it. A notch in the ice that lay past the step from the start is left out.
TEST(MeasureWindow, PassedFrameEndsAtTheIceThatCameOverTheStep) {
  SlabSpec spec;
  ParticleSnapshot s = slab_past_a_step(spec, {{.x_m = 300.0, .depth_m = 30.0},
                                               {.x_m = 600.0, .depth_m = 30.0},
                                               {.x_m = 1200.0, .depth_m = 30.0}});
  MeasureSettings passed;
  passed.frame = "passed";
  const CrevasseMeasurement m = measure_crevasses(s, passed);
  EXPECT_EQ(m.settings.frame, "passed");
  EXPECT_DOUBLE_EQ(m.settings.window_min_x_m, 150.0);
  EXPECT_DOUBLE_EQ(m.settings.window_max_x_m, 850.0);
  ASSERT_EQ(m.crevasses.size(), 2u);
  EXPECT_NEAR(m.crevasses[1].x_m, 600.0, spec.dx_m);
  s.upstream_ice_front_x_m = 0.0;  // no record of where the ice came from
  EXPECT_THROW(measure_crevasses(s, passed), std::invalid_argument);
}

// The "draped" frame measures the rest of the ice past the step, what lay there from the start:
// from the front of the ice that started upstream of the step to half an H_i behind the front.
TEST(MeasureWindow, DrapedFrameHoldsTheIceThatLayPastTheStepFromTheStart) {
  SlabSpec spec;
  ParticleSnapshot s = slab_past_a_step(spec, {{.x_m = 600.0, .depth_m = 30.0},
                                               {.x_m = 1000.0, .depth_m = 30.0},
                                               {.x_m = 1300.0, .depth_m = 30.0},
                                               {.x_m = 1975.0, .depth_m = 30.0}});
  MeasureSettings draped;
  draped.frame = "draped";
  const CrevasseMeasurement m = measure_crevasses(s, draped);
  EXPECT_EQ(m.settings.frame, "draped");
  EXPECT_DOUBLE_EQ(m.settings.window_min_x_m, 900.0);
  EXPECT_DOUBLE_EQ(m.settings.window_max_x_m, s.front_x() - 0.5 * spec.thickness_m);
  ASSERT_EQ(m.crevasses.size(), 2u);
  EXPECT_NEAR(m.crevasses[0].x_m, 1000.0, spec.dx_m);
  EXPECT_NEAR(m.crevasses[1].x_m, 1300.0, spec.dx_m);
  s.upstream_ice_front_x_m = 0.0;
  EXPECT_THROW(measure_crevasses(s, draped), std::invalid_argument);
}

// Damage every particle of `s` inside the box [x0, x1] × [z0, z1] (to the notches' ε_v^p).
void damage_box(ParticleSnapshot& s, const SlabSpec& spec, double x0, double x1, double z0, double z1) {
  for (std::size_t p = 0; p < s.size(); ++p)
    if (s.x[p] >= x0 && s.x[p] <= x1 && s.z[p] >= z0 && s.z[p] <= z1) s.eps_v_p[p] = spec.notch_eps_v_p;
}

// Two crevasses joined at depth by a damaged layer along the bed are one damaged cluster, but
// two crevasses: each where it meets the surface, each reaching the bed through the layer
// (full depth). A third, apart, keeps its partial depth.
TEST(MeasureJoined, CrevassesJoinedAlongTheBedAreCountedAtEachOpeningAndReachTheBed) {
  SlabSpec spec;
  const double h = test::spacing_of(spec);
  ParticleSnapshot s = make_slab(spec, {{.x_m = 402.5, .depth_m = 40.0},
                                        {.x_m = 602.5, .depth_m = 60.0},
                                        {.x_m = 902.5, .depth_m = 30.0}});
  damage_box(s, spec, 400.0, 605.0, 0.0, 10.0);               // the layer along the bed
  damage_box(s, spec, 400.0, 405.0, 0.0, spec.thickness_m);  // the first notch reaches it,
  damage_box(s, spec, 600.0, 605.0, 0.0, spec.thickness_m);  // and so does the second
  const CrevasseMeasurement m = measure_crevasses(s);
  EXPECT_EQ(m.cluster_count, 2u);
  ASSERT_EQ(m.crevasses.size(), 3u);
  EXPECT_NEAR(m.crevasses[0].x_m, 402.5, h);
  EXPECT_NEAR(m.crevasses[0].depth_m, spec.thickness_m, h);
  EXPECT_NEAR(m.crevasses[1].x_m, 602.5, h);
  EXPECT_NEAR(m.crevasses[1].depth_m, spec.thickness_m, h);
  EXPECT_NEAR(m.crevasses[2].x_m, 902.5, h);
  EXPECT_NEAR(m.crevasses[2].depth_m, 30.0, h);
  ASSERT_EQ(m.spacings_m.size(), 2u);
  EXPECT_NEAR(m.spacings_m[0], 200.0, h);
}

// A crevasse that branches: one stem from 40 to 80 m deep, two arms to the surface 60 m apart.
// Two openings, two crevasses, each as deep as the stem.
TEST(MeasureBranched, BranchedCrevasseHasACrevasseAtEachArm) {
  SlabSpec spec;
  const double h = test::spacing_of(spec);
  const double top = spec.thickness_m;
  ParticleSnapshot s = make_slab(spec, {{.x_m = 502.5, .depth_m = 45.0}, {.x_m = 562.5, .depth_m = 45.0}});
  damage_box(s, spec, 500.0, 565.0, top - 45.0, top - 40.0);  // the arms' common root
  damage_box(s, spec, 530.0, 535.0, top - 80.0, top - 40.0);  // the stem
  const CrevasseMeasurement m = measure_crevasses(s);
  EXPECT_EQ(m.cluster_count, 1u);
  ASSERT_EQ(m.crevasses.size(), 2u);
  EXPECT_NEAR(m.crevasses[0].x_m, 502.5, h);
  EXPECT_NEAR(m.crevasses[1].x_m, 562.5, h);
  for (const Crevasse& c : m.crevasses) EXPECT_NEAR(c.depth_m, 80.0, h);
  // Its arms' root lies deeper than the depth floor: no skin, and split_under_skin reads it alike.
  MeasureSettings under;
  under.split_under_skin = true;
  const CrevasseMeasurement u = measure_crevasses(s, under);
  ASSERT_EQ(u.crevasses.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(u.crevasses[k].x_m, m.crevasses[k].x_m);
    EXPECT_EQ(u.crevasses[k].depth_m, m.crevasses[k].depth_m);
  }
}

// A row of cracks hanging from a damaged skin (the top 10 m lost its strength from 395 to 610 m):
// one cluster that meets the surface all along the row. As it stands it is one crevasse; read
// under the skin (split_under_skin), each crack is a crevasse at its own position and depth.
TEST(MeasureSkin, CracksUnderADamagedSkinAreCrevassesOfTheirOwnWhenAsked) {
  SlabSpec spec;
  const double h = test::spacing_of(spec);
  std::vector<Notch> row;
  const std::vector<double> depths = {45.0, 60.0, 40.0, 55.0, 45.0};
  for (std::size_t k = 0; k < depths.size(); ++k)
    row.push_back({.x_m = 402.5 + 50.0 * static_cast<double>(k), .depth_m = depths[k]});
  ParticleSnapshot s = make_slab(spec, row);
  damage_box(s, spec, 395.0, 610.0, spec.thickness_m - 10.0, spec.thickness_m);
  const CrevasseMeasurement one = measure_crevasses(s);
  EXPECT_EQ(one.cluster_count, 1u);
  ASSERT_EQ(one.crevasses.size(), 1u);
  EXPECT_NEAR(one.crevasses[0].depth_m, 60.0, h);

  MeasureSettings under;
  under.split_under_skin = true;
  const CrevasseMeasurement split = measure_crevasses(s, under);
  ASSERT_EQ(split.crevasses.size(), depths.size());
  for (std::size_t k = 0; k < depths.size(); ++k) {
    EXPECT_NEAR(split.crevasses[k].x_m, 402.5 + 50.0 * static_cast<double>(k), h) << k;
    EXPECT_NEAR(split.crevasses[k].depth_m, depths[k], h) << k;
  }
  for (double spacing : split.spacings_m) EXPECT_NEAR(spacing, 50.0, h);
  // Separate cracks without a skin are read the same either way.
  const ParticleSnapshot bare = make_slab(spec, row);
  EXPECT_EQ(measure_crevasses(bare, under).crevasses.size(), measure_crevasses(bare).crevasses.size());
}

// The resolution floor c/(ρ_i g) ≥ 3 dx holds on the floor itself: a study that sets Π = 3 dx/H_i
// (0.075 at H_i = 400 m) derives c = Π ρ_i g H_i, 1 ulp short of 30 m, and that case is resolved.
TEST(MeasureResolution, TheFloorItselfIsResolved) {
  const double rho = 917.0, g = 9.81, dx = 10.0;
  for (const double h : {400.0, 600.0, 800.0}) {
    const double pi_floor = 3.0 * dx / h;
    EXPECT_FALSE(strength_under_resolved(pi_floor * rho * g * h, rho, g, dx)) << h;
    EXPECT_TRUE(strength_under_resolved(0.99 * pi_floor * rho * g * h, rho, g, dx)) << h;
  }
}

TEST(MeasureSlope, DepthIsRelativeToTheLocalSurfaceOnASlope) {
  // The surface drops 200 m over the slab (slope 0.1): a global surface height would be wrong
  // by up to 200 m.
  SlabSpec spec{.x_max_m = 2000.0, .noise_over_spacing = 0.2};
  spec.base_z = [](double x) { return -0.1 * x; };
  const auto notches = notch_train(spec, 80.0, {30.0, 60.0});
  // Notches at the 3-cell depth floor: the floor is off, this test is about the surface.
  MeasureSettings no_floor;
  no_floor.min_depth_over_dx = 0.0;
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches), no_floor);
  // One cell: lattice placement and noise; on a slope a dx-bin also spans 1 m of height.
  expect_matches(m, notches, spec.dx_m);
  expect_measurement_finite(m);
}

TEST(MeasureCurved, DepthIsRelativeToTheLocalSurfaceOnACurvedSurface) {
  // Ice draped over a smooth 80 m step: surface height changes by tens of metres along x,
  // with both convex and concave bends.
  SlabSpec spec{.thickness_m = 150.0, .x_max_m = 2500.0, .noise_over_spacing = 0.2};
  spec.base_z = [](double x) { return -40.0 * std::tanh((x - 1200.0) / 200.0); };
  const auto notches = notch_train(spec, 60.0, {40.0, 75.0, 20.0});
  // Notches below the 3-cell depth floor: the floor is off, this test is about the surface.
  MeasureSettings no_floor;
  no_floor.min_depth_over_dx = 0.0;
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches), no_floor);
  // One cell, as above; the bridge and the lips add < 1 m on these curvatures.
  expect_matches(m, notches, spec.dx_m);
  expect_measurement_finite(m);
}

TEST(MeasureCurved, DepthFollowsTheSurfaceOfIceDraggedOverARamp) {
  // Piecewise-linear draping: plateau, ramp of slope 0.3, floor (sharp bends).
  SlabSpec spec{.x_max_m = 2000.0, .noise_over_spacing = 0.1};
  spec.base_z = [](double x) {
    return x < 600.0 ? 90.0 : (x < 900.0 ? 90.0 - 0.3 * (x - 600.0) : 0.0);
  };
  const auto notches = notch_train(spec, 70.0, {30.0, 50.0});
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches));
  // One cell. At the concave bend the bridge can lift the lips by up to slope change ×
  // half-width / 2 = 0.3 × 25 m / 2 ≈ 4 m, inside that cell.
  expect_matches(m, notches, spec.dx_m);
}

TEST(MeasureOpen, WideOpenCrevasseIsMeasuredFromItsLips) {
  // A V-shaped opening 60 m wide at the surface (wider than the ±25 m bridge) down to a tip
  // 60 m deep: no particles in the gap, damaged walls one spacing thick, intact ice below. Inside
  // the gap the "highest undamaged particle" surface drops to the tip; the lips do not.
  SlabSpec spec{.x_max_m = 1000.0};
  ParticleSnapshot slab = make_slab(spec, {});
  const double h = test::spacing_of(spec), x_c = 500.0, z_tip = 40.0, half_top = 30.0;
  auto gap_half_width = [&](double z) { return half_top * (z - z_tip) / (100.0 - z_tip); };
  ParticleSnapshot open = slab;
  open.x.clear();
  open.z.clear();
  open.eps_v_p.clear();
  double z_lowest_damaged = 1e9;
  for (std::size_t i = 0; i < slab.size(); ++i) {
    const double d = std::abs(slab.x[i] - x_c) - gap_half_width(slab.z[i]);
    if (slab.z[i] > z_tip && d < 0.0) continue;  // inside the opening
    const bool wall = slab.z[i] > z_tip - 1.5 * h && d < 1.2 * h;
    if (wall) z_lowest_damaged = std::min(z_lowest_damaged, slab.z[i]);
    open.x.push_back(slab.x[i]);
    open.z.push_back(slab.z[i]);
    open.eps_v_p.push_back(wall ? spec.notch_eps_v_p : 0.0);
  }
  const CrevasseMeasurement m = measure_crevasses(open);
  ASSERT_EQ(m.crevasses.size(), 1u);
  // One cell: the walls are resolved on the lattice.
  EXPECT_NEAR(m.crevasses[0].x_m, x_c, spec.dx_m);
  EXPECT_NEAR(m.crevasses[0].surface_z_m, 100.0, spec.dx_m);
  EXPECT_NEAR(m.crevasses[0].depth_m, 100.0 - (z_lowest_damaged - 0.5 * h), spec.dx_m);
  EXPECT_GT(m.crevasses[0].width_m, 2.0 * half_top);
}

TEST(MeasureFragmented, FullyDamagedSlabIsFlaggedAndFinite) {
  SlabSpec spec{.x_max_m = 1000.0};
  const CrevasseMeasurement m = measure_crevasses(
      make_slab(spec, {{.x_m = 500.0, .depth_m = spec.thickness_m, .width_m = 2000.0}}));
  EXPECT_TRUE(m.flags.fragmented);
  EXPECT_EQ(m.damaged_particle_count, m.particle_count);
  EXPECT_FALSE(m.flags.has_spacing);
  EXPECT_LE(m.crevasses.size(), 1u);
  expect_measurement_finite(m);
}

TEST(MeasureFragmented, MostlyDamagedWindowIsFlagged) {
  SlabSpec spec{.x_max_m = 1000.0};
  // Damaged columns 15 m wide every 20 m: three quarters of the ice is broken.
  std::vector<Notch> notches;
  for (double x = 100.0; x < 1000.0; x += 20.0)
    notches.push_back({.x_m = x, .depth_m = 100.0, .width_m = 15.0});
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches));
  EXPECT_TRUE(m.flags.fragmented);
  expect_measurement_finite(m);
}

TEST(MeasureWindow, EmptyWindowIsFlaggedNotAnError) {
  const auto slab = make_slab({}, {{.x_m = 500.0, .depth_m = 30.0}});
  MeasureSettings inverted;
  inverted.window_min_x_m = 800.0;
  inverted.window_max_x_m = 700.0;
  const CrevasseMeasurement a = measure_crevasses(slab, inverted);
  EXPECT_TRUE(a.flags.empty_window);
  EXPECT_TRUE(a.flags.no_crevasse);
  EXPECT_TRUE(a.crevasses.empty());
  expect_measurement_finite(a);

  MeasureSettings beyond_front;  // the front has not yet travelled past the window
  beyond_front.window_min_x_m = 5000.0;
  beyond_front.window_max_x_m = 6000.0;
  const CrevasseMeasurement b = measure_crevasses(slab, beyond_front);
  EXPECT_TRUE(b.flags.empty_window);
  EXPECT_EQ(b.window_particle_count, 0u);
  expect_measurement_finite(b);
}

TEST(MeasureWindow, DefaultWindowExcludesStepAndFrontZones) {
  SlabSpec spec{.x_max_m = 1000.0};
  // 30 m past the step foot and 20 m before the front: both inside the 0.5·H_i margins.
  const std::vector<Notch> notches = {{.x_m = 30.0, .depth_m = 30.0},
                                      {.x_m = 500.0, .depth_m = 30.0},
                                      {.x_m = 980.0, .depth_m = 30.0}};
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches));
  EXPECT_DOUBLE_EQ(m.settings.window_min_x_m, 50.0);
  EXPECT_DOUBLE_EQ(m.settings.window_max_x_m, 997.5 - 50.0);  // front = last column centre
  ASSERT_EQ(m.crevasses.size(), 1u);
  EXPECT_FALSE(m.flags.has_spacing);
}

TEST(MeasureEmpty, EmptySnapshotGivesDefinedResult) {
  const CrevasseMeasurement m = measure_crevasses(ParticleSnapshot{});
  EXPECT_TRUE(m.flags.empty_snapshot);
  EXPECT_TRUE(m.flags.empty_window);
  EXPECT_TRUE(m.flags.no_crevasse);
  EXPECT_TRUE(m.crevasses.empty());
  expect_measurement_finite(m);
}

TEST(MeasureInvalid, InconsistentSnapshotThrowsWithTheField) {
  auto slab = make_slab({.x_max_m = 500.0}, {});
  slab.eps_v_p.pop_back();
  try {
    measure_crevasses(slab);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("eps_v_p"), std::string::npos) << e.what();
  }
  auto no_dx = make_slab({.x_max_m = 500.0}, {});
  no_dx.dx_m = 0.0;
  EXPECT_THROW(measure_crevasses(no_dx), std::invalid_argument);
  MeasureSettings override_dx;
  override_dx.dx_m = 10.0;
  EXPECT_NO_THROW(measure_crevasses(no_dx, override_dx));
}

TEST(MeasureThreshold, WithoutSofteningTheAbsoluteThresholdApplies) {
  SlabSpec spec{.softening_zeta = 0.0, .notch_eps_v_p = 0.02};
  const std::vector<Notch> notches = {{.x_m = 400.0, .depth_m = 40.0},
                                      {.x_m = 600.0, .depth_m = 40.0}};
  const auto slab = make_slab(spec, notches);
  const CrevasseMeasurement m = measure_crevasses(slab);  // default threshold 0.01 < 0.02
  EXPECT_EQ(m.crevasses.size(), 2u);
  EXPECT_FALSE(m.settings.threshold_from_softening);
  MeasureSettings strict;
  strict.eps_v_p_threshold = 0.05;
  EXPECT_TRUE(measure_crevasses(slab, strict).flags.no_crevasse);
}

TEST(MeasureThreshold, SoftenedThresholdIsThreeOverZeta) {
  // 1 − exp(−ζ ε) = 0.95 ⇔ ε = ln(20)/ζ ≈ 3/ζ: just below is intact, just above damaged.
  const double eps_threshold = std::log(20.0) / 500.0;
  SlabSpec below{.notch_eps_v_p = 0.99 * eps_threshold};
  SlabSpec above{.notch_eps_v_p = 1.01 * eps_threshold};
  const std::vector<Notch> notch = {{.x_m = 500.0, .depth_m = 40.0}};
  EXPECT_TRUE(measure_crevasses(make_slab(below, notch)).flags.no_crevasse);
  EXPECT_EQ(measure_crevasses(make_slab(above, notch)).crevasses.size(), 1u);
}

TEST(Measure3D, CentralBandGivesTheSameCrevasses) {
  SlabSpec spec{.dim = 3, .x_max_m = 1000.0, .width_m = 60.0, .noise_over_spacing = 0.2};
  const auto notches = notch_train(spec, 60.0, {30.0, 50.0});
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches));
  EXPECT_EQ(m.settings.dim, 3);
  EXPECT_NEAR(m.settings.y_band_center_m, 30.0, 1.0);  // middle of [0, 60] m up to the noise
  EXPECT_LT(m.particle_count, make_slab(spec, notches).size());
  // One cell, as in 2D.
  expect_matches(m, notches, spec.dx_m);
  expect_measurement_finite(m);
}

// Scale: a million particles are measured correctly. No time bound here (speed belongs in
// benchmarks); the time is recorded as a test property, and an accidental O(N²) would show as a
// ctest timeout (minutes instead of ~0.3 s).
TEST(MeasureScale, MillionParticlesAreMeasured) {
  // 12.5 km × 125 m at 1.25 m particle spacing: 10^6 particles.
  SlabSpec spec{.dx_m = 2.5, .thickness_m = 125.0, .x_max_m = 12500.0, .noise_over_spacing = 0.2};
  const auto notches = notch_train(spec, 50.0, {30.0, 60.0});
  const auto slab = make_slab(spec, notches);
  ASSERT_GE(slab.size(), 1'000'000u);
  const auto start = std::chrono::steady_clock::now();
  const CrevasseMeasurement m = measure_crevasses(slab);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(m.crevasses.size(), notches.size());
  RecordProperty("measure_seconds", std::to_string(seconds));
}

TEST(MeasureWriters, CsvAndJsonAreParseable) {
  SlabSpec spec{.x_max_m = 1000.0};
  const auto notches = notch_train(spec, 100.0, {30.0});
  const CrevasseMeasurement m = measure_crevasses(make_slab(spec, notches));
  const auto dir = std::filesystem::temp_directory_path() / "crevasse_measure_writers";
  std::filesystem::create_directories(dir);
  write_crevasses_csv(m, dir / "crevasses.csv");
  write_measurement_summary(m, dir / "summary.json");

  std::ifstream csv(dir / "crevasses.csv");
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  EXPECT_EQ(line, "index,x_m,depth_m,width_m,depth_over_H,spacing_to_next_m");
  std::size_t rows = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> fields;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) fields.push_back(f);
    if (!line.empty() && line.back() == ',') fields.push_back("");
    ASSERT_EQ(fields.size(), 6u) << line;
    EXPECT_EQ(std::stoul(fields[0]), rows);
    EXPECT_NEAR(std::stod(fields[1]), m.crevasses[rows].x_m, 1e-6);
    EXPECT_NEAR(std::stod(fields[4]), m.crevasses[rows].depth_m / 100.0, 1e-9);
    const bool last = rows + 1 == m.crevasses.size();
    EXPECT_EQ(fields[5].empty(), last) << line;
    EXPECT_EQ(line.find("nan"), std::string::npos);
    ++rows;
  }
  EXPECT_EQ(rows, m.crevasses.size());

  std::ifstream js(dir / "summary.json");
  const nlohmann::json j = nlohmann::json::parse(js);
  EXPECT_EQ(j["crevasse_count"].get<std::size_t>(), m.crevasses.size());
  EXPECT_EQ(j["dropped_spacing_count"].get<std::size_t>(), 0u);
  EXPECT_NEAR(j["spacing_m"]["median"].get<double>(), 100.0, 1e-9);
  EXPECT_NEAR(j["spacing_over_h"]["median"].get<double>(), 1.0, 1e-9);
  EXPECT_TRUE(j["flags"]["has_spacing"].get<bool>());
  EXPECT_DOUBLE_EQ(j["settings"]["damage_threshold"].get<double>(), 0.95);
  EXPECT_DOUBLE_EQ(j["settings"]["resolution_floor_m"].get<double>(), 30.0);
  EXPECT_EQ(j["positions_m"].size(), m.crevasses.size());
  expect_all_finite(j);

  // No crevasse: statistics are null, never NaN, and the flags say why.
  const nlohmann::json none = measurement_summary_json(measure_crevasses(make_slab(spec, {})));
  EXPECT_TRUE(none["spacing_m"].is_null());
  EXPECT_TRUE(none["flags"]["no_crevasse"].get<bool>());
  EXPECT_FALSE(none["flags"]["has_spacing"].get<bool>());
  std::filesystem::remove_all(dir);
}

TEST(MeasureWriters, UnwritablePathThrowsWithThePath) {
  const CrevasseMeasurement m = measure_crevasses(ParticleSnapshot{});
  try {
    write_crevasses_csv(m, "/nonexistent-dir/crevasses.csv");
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/crevasses.csv"), std::string::npos);
  }
}


// How broken the window is, on a constructed field (H_i = 100 m, particles 5 m apart, window
// [0, 2000] m: 400 columns of 20 particles, 10 of them more than H_i/2 below the surface).
// A partial-depth surface crevasse 30 m deep and 6 columns wide leaves the deep share at zero;
// a buried band from 60 m below the surface to the bed, 40 columns wide, damages 8 of the 10
// deep rows there: 320 of the window's 4000 deep particles.
TEST(MeasureDamage, DeepShareSeesIceBrokenUnderItsSurfaceOnly) {
  SlabSpec spec;
  MeasureSettings whole;
  whole.frame = "final";
  whole.window_min_x_m = 0.0;
  whole.window_max_x_m = 2000.0;
  const CrevasseMeasurement surface_only =
      measure_crevasses(make_slab(spec, {{.x_m = 500.0, .depth_m = 30.0, .width_m = 30.0}}), whole);
  ASSERT_EQ(surface_only.crevasses.size(), 1u);
  EXPECT_EQ(surface_only.window_particle_count, 8000u);
  EXPECT_EQ(surface_only.window_damaged_count, 6u * 6u);
  EXPECT_EQ(surface_only.deep_particle_count, 4000u);
  EXPECT_EQ(surface_only.deep_damaged_count, 0u);

  const CrevasseMeasurement buried = measure_crevasses(
      make_slab(spec, {{.x_m = 500.0, .depth_m = 30.0, .width_m = 30.0},
                       {.x_m = 1200.0, .depth_m = 100.0, .width_m = 200.0, .top_gap_m = 60.0}}),
      whole);
  EXPECT_EQ(buried.crevasses.size(), 1u) << "buried damage is not a crevasse";
  EXPECT_EQ(buried.deep_particle_count, 4000u);
  EXPECT_EQ(buried.deep_damaged_count, 320u);
  const nlohmann::json j = measurement_summary_json(buried);
  EXPECT_DOUBLE_EQ(j["damage"]["deep_damaged_fraction"].get<double>(), 0.08);
  EXPECT_DOUBLE_EQ(j["damage"]["window_damaged_fraction"].get<double>(), (36.0 + 320.0) / 8000.0);
}

}  // namespace
}  // namespace crevasse::analysis
