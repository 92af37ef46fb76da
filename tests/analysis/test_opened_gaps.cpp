// Opened gaps (measurement.count_gaps, analysis/opened_gaps.hpp): a crack whose walls have
// separated is empty space between intact ice. On a constructed slab with such a crack, damaged
// only in a thin rim at the surface, the damaged particles alone see the rim; counting the gap
// sees the crack to its bottom, within one cell. Ice without holes measures the same either way.
#include <gtest/gtest.h>

#include <cmath>

#include "analysis/crevasse_measure.hpp"
#include "analysis/opened_gaps.hpp"
#include "synthetic_slab.hpp"

namespace crevasse::analysis {
namespace {

// Removes every particle inside [x0, x1] × [z0, z1]: an opened crack.
void open_gap(ParticleSnapshot& s, double x0, double x1, double z0, double z1) {
  ParticleSnapshot out = s;
  for (auto* v : {&out.x, &out.y, &out.z, &out.vx, &out.vy, &out.vz, &out.eps_v_p, &out.pressure_pa,
                  &out.von_mises_pa, &out.sigma_zz_pa, &out.volume_m3})
    v->clear();
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.x[i] >= x0 && s.x[i] <= x1 && s.z[i] >= z0 && s.z[i] <= z1) continue;
    out.x.push_back(s.x[i]);
    out.z.push_back(s.z[i]);
    out.vx.push_back(s.vx[i]);
    out.vz.push_back(s.vz[i]);
    out.eps_v_p.push_back(s.eps_v_p[i]);
    out.pressure_pa.push_back(s.pressure_pa[i]);
    out.von_mises_pa.push_back(s.von_mises_pa[i]);
    out.sigma_zz_pa.push_back(s.sigma_zz_pa[i]);
    out.volume_m3.push_back(s.volume_m3[i]);
  }
  s = out;
}

MeasureSettings final_frame(bool gaps) {
  MeasureSettings m;
  m.frame = "final";
  m.window_min_x_m = 200.0;
  m.window_max_x_m = 1800.0;
  m.count_gaps = gaps;
  return m;
}

TEST(OpenedGaps, ACrackOfEmptySpaceIsMeasuredToItsBottom) {
  test::SlabSpec spec;  // H_i = 100 m, dx = 10 m, surface at z = 100 m
  spec.thickness_m = 200.0;
  // Two cracks 30 m wide, open from the surface (z = 200 m), their walls damaged in a 40 m
  // rim: at x = 600 m open to 150 m depth, at x = 1200 m to 90 m. A buried hole at x = 1500 m
  // reaches no surface and is not a crevasse.
  ParticleSnapshot s = test::make_slab(spec, {{582.5, 40.0, 0.0}, {617.5, 40.0, 0.0},
                                              {1182.5, 40.0, 0.0}, {1217.5, 40.0, 0.0}});
  open_gap(s, 585.0, 615.0, 50.0, 200.0);
  open_gap(s, 1185.0, 1215.0, 110.0, 200.0);
  open_gap(s, 1480.0, 1520.0, 60.0, 120.0);
  const CrevasseMeasurement without = measure_crevasses(s, final_frame(false));
  const CrevasseMeasurement with = measure_crevasses(s, final_frame(true));
  // Without the gaps each wall is a crevasse of its own (35 m apart), as deep as its rim.
  ASSERT_EQ(without.crevasses.size(), 4u);
  ASSERT_EQ(with.crevasses.size(), 2u);
  for (const Crevasse& c : without.crevasses) EXPECT_LT(c.depth_m, 50.0) << c.x_m;  // the rim only
  EXPECT_NEAR(with.crevasses[0].x_m, 600.0, 10.0);
  EXPECT_NEAR(with.crevasses[0].depth_m, 150.0, 10.0);
  EXPECT_NEAR(with.crevasses[1].x_m, 1200.0, 10.0);
  EXPECT_NEAR(with.crevasses[1].depth_m, 90.0, 10.0);
  // The counts are of particles: gap points are not particles.
  EXPECT_EQ(with.particle_count, without.particle_count);
  EXPECT_EQ(with.damaged_particle_count, without.damaged_particle_count);
  EXPECT_EQ(with.window_damaged_count, without.window_damaged_count);
}

// A dip in the surface that the bridged profile spans, between walls of intact ice, is not a
// crack: counting gaps reads no crevasse there, while the same dip with a damaged wall is one.
TEST(OpenedGaps, ADipBetweenIntactWallsIsNotACrack) {
  test::SlabSpec spec;
  spec.thickness_m = 200.0;  // bridged over up to 2 x 50 m
  ParticleSnapshot intact = test::make_slab(spec, {});
  open_gap(intact, 985.0, 1035.0, 160.0, 200.0);  // 50 m wide, 40 m deep
  const CrevasseMeasurement dip = measure_crevasses(intact, final_frame(true));
  EXPECT_TRUE(dip.crevasses.empty()) << dip.crevasses.size() << " crevasse(s), the first "
                                     << (dip.crevasses.empty() ? 0.0 : dip.crevasses[0].depth_m) << " m deep";

  ParticleSnapshot cracked = test::make_slab(spec, {{1037.5, 20.0, 0.0}});  // its right wall damaged
  open_gap(cracked, 985.0, 1035.0, 160.0, 200.0);
  const CrevasseMeasurement crack = measure_crevasses(cracked, final_frame(true));
  ASSERT_EQ(crack.crevasses.size(), 1u);
  EXPECT_NEAR(crack.crevasses[0].depth_m, 40.0, 10.0);
}

// A parted crack leaves a notch beside it at the surface. The notch's gap joins the crack and
// may carry its depth, but the crack is where its damaged particles meet the surface.
TEST(OpenedGaps, ANotchBesideACrackDoesNotMoveIt) {
  test::SlabSpec spec;
  spec.thickness_m = 200.0;
  ParticleSnapshot s = test::make_slab(spec, {{1002.5, 100.0, 0.0}});
  open_gap(s, 945.0, 1000.0, 175.0, 200.0);  // a notch 55 m wide, 25 m deep, against the crack
  const CrevasseMeasurement without = measure_crevasses(s, final_frame(false));
  const CrevasseMeasurement with = measure_crevasses(s, final_frame(true));
  ASSERT_EQ(without.crevasses.size(), 1u);
  ASSERT_EQ(with.crevasses.size(), 1u);
  EXPECT_NEAR(without.crevasses[0].x_m, 1002.5, 1.0);
  EXPECT_EQ(with.crevasses[0].x_m, without.crevasses[0].x_m);
  EXPECT_NEAR(with.crevasses[0].depth_m, without.crevasses[0].depth_m, 5.0);
}

// Where no damaged particle reaches the surface, the gap above damaged ice places the crevasse:
// the opened mouth of a crack, deeper than it is wide. A sag of the surface over damaged ice,
// wider than it is deep (two blocks tilted beside a crack's lip), is not a crack.
TEST(OpenedGaps, AnOpenedMouthIsDeeperThanWideASagIsNot) {
  test::SlabSpec spec;
  spec.thickness_m = 200.0;
  // A crack damaged from 60 to 100 m below the surface, open above: a mouth 20 m wide.
  ParticleSnapshot mouth = test::make_slab(spec, {{600.0, 100.0, 20.0, 60.0}});
  open_gap(mouth, 590.0, 610.0, 140.0, 200.0);
  // A sag 90 m wide and 35 m deep over a damaged layer 10 m thick.
  ParticleSnapshot sag = test::make_slab(spec, {{1045.0, 45.0, 90.0, 35.0}});
  open_gap(sag, 1000.0, 1090.0, 165.0, 200.0);
  const CrevasseMeasurement m = measure_crevasses(mouth, final_frame(true));
  ASSERT_EQ(m.crevasses.size(), 1u);
  EXPECT_NEAR(m.crevasses[0].x_m, 600.0, 10.0);
  EXPECT_NEAR(m.crevasses[0].depth_m, 100.0, 10.0);
  const CrevasseMeasurement g = measure_crevasses(sag, final_frame(true));
  EXPECT_TRUE(g.crevasses.empty()) << g.crevasses.size() << " crevasse(s), the first "
                                   << (g.crevasses.empty() ? 0.0 : g.crevasses[0].depth_m) << " m deep, "
                                   << (g.crevasses.empty() ? 0.0 : g.crevasses[0].width_m) << " m wide";
}

TEST(OpenedGaps, IceWithoutHolesHasNoGapsAndMeasuresTheSame) {
  test::SlabSpec spec;
  spec.noise_over_spacing = 0.2;
  spec.base_z = [](double x) { return x < 1000.0 ? 0.0 : -0.5 * (x - 1000.0); };  // a 1:2 ramp
  const ParticleSnapshot s =
      test::make_slab(spec, {{400.0, 40.0, 10.0}, {700.0, 60.0, 10.0}, {1300.0, 30.0, 10.0}});
  const CrevasseMeasurement a = measure_crevasses(s, final_frame(false));
  const CrevasseMeasurement b = measure_crevasses(s, final_frame(true));
  ASSERT_EQ(a.crevasses.size(), 3u);
  ASSERT_EQ(b.crevasses.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(a.crevasses[i].depth_m, b.crevasses[i].depth_m) << i;
  std::vector<std::array<double, 2>> bed;
  for (double x = -10.0; x <= 2010.0; x += 5.0) bed.push_back({x, spec.base_z(x)});
  EXPECT_EQ(find_opened_gaps(s.x, s.z, std::vector<std::uint8_t>(s.size(), 1), a.surface, bed, 10.0, 5.0).cell_count, 0u);
}

}  // namespace
}  // namespace crevasse::analysis
