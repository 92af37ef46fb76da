// Quadratic B-spline weights (engine/bspline.hpp): the properties MLS-MPM relies on.
//  * partition of unity Σ w_i = 1 (mass and momentum transfer conserve their totals);
//  * linear reproduction Σ w_i x_i = x_p, i.e. Σ w_i (x_i − x_p) = 0 (the stress term of P2G
//    adds no net force, and APIC transfers keep affine fields exact);
//  * second moment Σ w_i (x_i − x_p)(x_i − x_p)ᵀ = dx²/4 · I, the inertia tensor D whose inverse
//    4/dx² the P2G and G2P stages hard-code (Jiang et al. 2015, APIC, §5.3).
#include <gtest/gtest.h>

#include <random>

#include "engine/bspline.hpp"

namespace crevasse {
namespace {

// Round-off: each sum has 3^Dim terms of size ≤ |x|/dx ~ 1e3 in grid units, so a few 1e-13
// absolute is the double-precision floor; 1e-12 leaves a margin and is still 10 orders of
// magnitude below any real error (a wrong weight formula breaks these by O(0.1)).
constexpr double kRoundOff = 1e-12;

TEST(BSpline, OneDimensionalWeightsAreNonNegativeAndReproduceLinearFunctions) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> pos(-500.0, 500.0);
  for (int trial = 0; trial < 10000; ++trial) {
    const double xi = pos(rng);
    const QuadraticWeights1d w = quadratic_weights(xi);
    double sum = 0.0, first = 0.0, second = 0.0;
    for (int i = 0; i < 3; ++i) {
      EXPECT_GE(w.w[i], 0.0);
      const double d = (w.base + i) - xi;
      EXPECT_LE(std::abs(d), 1.5);  // the stencil brackets the particle
      sum += w.w[i];
      first += w.w[i] * d;
      second += w.w[i] * d * d;
    }
    EXPECT_NEAR(sum, 1.0, kRoundOff) << "xi = " << xi;
    EXPECT_NEAR(first, 0.0, kRoundOff) << "xi = " << xi;
    EXPECT_NEAR(second, 0.25, kRoundOff) << "xi = " << xi;
  }
}

template <int Dim>
void check_stencil_moments(std::uint64_t seed, double dx) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> pos(-300.0, 300.0);
  for (int trial = 0; trial < 5000; ++trial) {
    Vec<Dim> xp;
    for (int a = 0; a < Dim; ++a) xp[a] = pos(rng);
    const Vec<Dim> xg = xp / dx;
    const StencilWeights<Dim> w(xg);
    const IVec<Dim> base = w.base();
    double sum = 0.0;
    Vec<Dim> weighted_position = Vec<Dim>::Zero();
    Vec<Dim> first = Vec<Dim>::Zero();
    Mat<Dim> second = Mat<Dim>::Zero();
    int nodes = 0;
    for_each_stencil_node<Dim>(w, [&](const IVec<Dim>& off, double wt) {
      ++nodes;
      EXPECT_DOUBLE_EQ(wt, w.weight(off));  // both access paths agree
      const Vec<Dim> xi = (base + off).template cast<double>() * dx;
      sum += wt;
      weighted_position += wt * xi;
      first += wt * (xi - xp);
      second += wt * (xi - xp) * (xi - xp).transpose();
    });
    EXPECT_EQ(nodes, Dim == 2 ? 9 : 27);
    EXPECT_NEAR(sum, 1.0, kRoundOff);
    // Positions are up to 300 m: relative round-off 1e-16 on sums of 27 terms of that size.
    EXPECT_NEAR((weighted_position - xp).norm(), 0.0, kRoundOff * 300.0);
    EXPECT_NEAR(first.norm(), 0.0, kRoundOff * 300.0);
    const Mat<Dim> expected = 0.25 * dx * dx * Mat<Dim>::Identity();
    EXPECT_NEAR((second - expected).norm(), 0.0, kRoundOff * 300.0 * dx);
  }
}

TEST(BSpline, StencilPartitionOfUnityAndLinearReproduction2d) {
  check_stencil_moments<2>(11, 1.0);
  check_stencil_moments<2>(12, 2.5);
}

TEST(BSpline, StencilPartitionOfUnityAndLinearReproduction3d) {
  check_stencil_moments<3>(21, 1.0);
  check_stencil_moments<3>(22, 0.37);
}

// Exactly on a node and exactly half-way between nodes are the branch points of the base index.
TEST(BSpline, WeightsAtNodesAndCellCentres) {
  const QuadraticWeights1d on_node = quadratic_weights(3.0);
  EXPECT_EQ(on_node.base, 2);
  EXPECT_DOUBLE_EQ(on_node.w[0], 0.125);
  EXPECT_DOUBLE_EQ(on_node.w[1], 0.75);
  EXPECT_DOUBLE_EQ(on_node.w[2], 0.125);
  const QuadraticWeights1d centre = quadratic_weights(3.5);
  EXPECT_EQ(centre.base, 3);
  EXPECT_DOUBLE_EQ(centre.w[0], 0.5);
  EXPECT_DOUBLE_EQ(centre.w[1], 0.5);
  EXPECT_DOUBLE_EQ(centre.w[2], 0.0);
}

}  // namespace
}  // namespace crevasse
