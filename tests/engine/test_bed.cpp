// The bed signed-distance function (engine/bed.hpp): sign (negative in rock), distance and
// outward normal against hand-computed geometry for the step, the vertical step, the concave
// trough and the flat bed.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/bed.hpp"

namespace crevasse {
namespace {

// Distances are computed from a handful of operations on lengths of ~100 m: 1e-9 m is round-off.
constexpr double kTol = 1e-9;

void expect_normal(const Bed::Point& n, double nx, double nz) {
  EXPECT_NEAR(n[0], nx, 1e-12);
  EXPECT_NEAR(n[1], nz, 1e-12);
}

TEST(Bed, StepPlateauRampAndFloor) {
  // Plateau at z = 50 up to x = 100, ramp to z = 0 at x = 200, floor to x = 500.
  const Bed bed = Bed::step(100.0, 50.0, 100.0, -20.0, 500.0);
  EXPECT_DOUBLE_EQ(bed.height_at(50.0), 50.0);
  EXPECT_DOUBLE_EQ(bed.height_at(150.0), 25.0);
  EXPECT_DOUBLE_EQ(bed.height_at(300.0), 0.0);
  // Above and inside the plateau, away from the corner.
  EXPECT_NEAR(bed.signed_distance(50.0, 60.0), 10.0, kTol);
  EXPECT_NEAR(bed.signed_distance(50.0, 45.0), -5.0, kTol);
  expect_normal(bed.normal(50.0, 60.0), 0.0, 1.0);
  expect_normal(bed.normal(50.0, 45.0), 0.0, 1.0);  // points out of the rock from inside too
  // Above the ramp: distance to the line z = 50 − (x − 100)/2, normal (1, 2)/√5.
  const double nx = 1.0 / std::sqrt(5.0), nz = 2.0 / std::sqrt(5.0);
  const double x = 150.0, z = 35.0;  // 10 m above the ramp surface at x = 150
  EXPECT_NEAR(bed.signed_distance(x, z), 10.0 * nz, kTol);
  expect_normal(bed.normal(x, z), nx, nz);
  EXPECT_NEAR(bed.signed_distance(150.0, 20.0), -5.0 * nz, kTol);
  // Near the convex corner at the top of the ramp, inside the wedge between the plateau normal
  // and the ramp normal, the closest point is the corner (100, 50) itself.
  EXPECT_NEAR(bed.signed_distance(101.0, 54.0), std::sqrt(17.0), kTol);
  expect_normal(bed.normal(101.0, 54.0), 1.0 / std::sqrt(17.0), 4.0 / std::sqrt(17.0));
  // Floor.
  EXPECT_NEAR(bed.signed_distance(400.0, 7.0), 7.0, kTol);
  EXPECT_NEAR(bed.signed_distance(400.0, -3.0), -3.0, kTol);
  // On the surface: zero distance and the segment's normal.
  EXPECT_NEAR(bed.signed_distance(150.0, 25.0), 0.0, kTol);
  expect_normal(bed.normal(150.0, 25.0), nx, nz);
}

TEST(Bed, VerticalStep) {
  // Cliff at x = 100 from z = 50 down to 0.
  const Bed bed = Bed::step(100.0, 50.0, 0.0, -20.0, 500.0);
  EXPECT_DOUBLE_EQ(bed.height_at(100.0), 50.0);  // the upper value on the vertical segment
  EXPECT_DOUBLE_EQ(bed.height_at(100.5), 0.0);
  // In front of the cliff face (air) and behind it (rock), 5 m from it, mid-height.
  EXPECT_NEAR(bed.signed_distance(105.0, 25.0), 5.0, kTol);
  expect_normal(bed.normal(105.0, 25.0), 1.0, 0.0);
  EXPECT_NEAR(bed.signed_distance(95.0, 25.0), -5.0, kTol);
  expect_normal(bed.normal(95.0, 25.0), 1.0, 0.0);
  // Inside the rock near the top: the plateau surface (2 m) is closer than the face (5 m).
  EXPECT_NEAR(bed.signed_distance(95.0, 48.0), -2.0, kTol);
  expect_normal(bed.normal(95.0, 48.0), 0.0, 1.0);
  // Beyond the cliff edge diagonally: the edge point (100, 50).
  EXPECT_NEAR(bed.signed_distance(103.0, 54.0), 5.0, kTol);
  // The foot of the cliff: a concave corner; the floor below-right is rock.
  EXPECT_NEAR(bed.signed_distance(110.0, -1.0), -1.0, kTol);
}

TEST(Bed, ConcaveTrough) {
  // z_b = h (1 − s)², s = (x − 100)/200, h = 60.
  const double h = 60.0, x_top = 100.0, len = 200.0;
  const Bed bed = Bed::concave(x_top, h, len, -20.0, 600.0);
  auto zb = [&](double x) {
    const double s = std::clamp((x - x_top) / len, 0.0, 1.0);
    return h * (1.0 - s) * (1.0 - s);
  };
  // The polyline has 48 chords: the sagitta of a chord is (2h/L²)(L/48)²/8 = h/(4·48²)
  // ≈ 6.5e-3 m here; 1e-2 m covers it.
  const double chord_tol = 1e-2;
  for (double x = 100.0; x <= 300.0; x += 7.3) EXPECT_NEAR(bed.height_at(x), zb(x), chord_tol);
  // Signed distance against a brute-force distance to the analytic curve.
  for (const auto& [px, pz] : {std::pair{150.0, 60.0}, std::pair{200.0, 5.0},
                               std::pair{250.0, -2.0}, std::pair{120.0, 30.0}}) {
    double best = 1e300;
    for (int i = 0; i <= 200000; ++i) {
      const double x = -20.0 + 620.0 * i / 200000.0;
      best = std::min(best, std::hypot(px - x, pz - zb(x)));
    }
    const double sign = pz < zb(px) ? -1.0 : 1.0;
    EXPECT_NEAR(bed.signed_distance(px, pz), sign * best, chord_tol) << px << ", " << pz;
  }
  // The trough is concave-up: slopes steepen towards the top, so normals tilt more there.
  const Bed::Point n_top = bed.normal(110.0, zb(110.0) + 1.0);
  const Bed::Point n_low = bed.normal(280.0, zb(280.0) + 1.0);
  EXPECT_GT(n_top[0], n_low[0]);
  EXPECT_GT(n_low[0], 0.0);
}

TEST(Bed, Flat) {
  const Bed bed = Bed::flat(3.0, -10.0, 50.0);
  for (const double x : {-5.0, 0.0, 20.0, 49.0}) {
    EXPECT_NEAR(bed.signed_distance(x, 7.0), 4.0, kTol);
    EXPECT_NEAR(bed.signed_distance(x, 1.0), -2.0, kTol);
    expect_normal(bed.normal(x, 7.0), 0.0, 1.0);
    expect_normal(bed.normal(x, 1.0), 0.0, 1.0);
    EXPECT_DOUBLE_EQ(bed.height_at(x), 3.0);
  }
}

}  // namespace
}  // namespace crevasse
