// Quadratic B-spline weights (engine/bspline.hpp): the properties MLS-MPM relies on.
//  * partition of unity Σ w_i = 1 (mass and momentum transfer conserve their totals);
//  * linear reproduction Σ w_i x_i = x_p, i.e. Σ w_i (x_i − x_p) = 0 (the stress term of P2G
//    adds no net force, and APIC transfers keep affine fields exact);
//  * second moment Σ w_i (x_i − x_p)(x_i − x_p)ᵀ = dx²/4 · I, the inertia tensor D whose inverse
//    4/dx² the P2G and G2P stages hard-code (Jiang et al. 2015, APIC, §5.3).
#include <gtest/gtest.h>

#include <random>

#include "engine/bspline.hpp"
#include "engine/grid.hpp"

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

// A grid box of spacing dx from node lo0 to lo0 + n0 − 1 along every axis (a little longer along
// the later axes, so that the flat strides differ from the box length).
template <int Dim>
Grid<Dim> test_grid(double dx, int lo0, int n0) {
  Grid<Dim> grid;
  grid.dx = dx;
  IVec<Dim> lo, n;
  for (int a = 0; a < Dim; ++a) {
    lo[a] = lo0;
    n[a] = n0 + 3 * a;
  }
  grid.reset(lo, n);
  return grid;
}

// The flat-index stencil loop visits the same nodes, in the same order and with the same
// weights, as the per-node loop with Grid::flat; StencilOffsets gives the same doubles as the
// per-node distance (node − x/dx)·dx. The stencil loops of simulation.cpp rest on both.
template <int Dim>
void check_flat_stencil(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> pos(-40.0, 40.0);
  Grid<Dim> grid = test_grid<Dim>(2.5, -20, 45);  // covers every stencil of |x/dx| ≤ 16
  const auto stride = grid.strides();
  for (int trial = 0; trial < 2000; ++trial) {
    Vec<Dim> xg;
    for (int a = 0; a < Dim; ++a) xg[a] = pos(rng) / grid.dx;
    const StencilWeights<Dim> w(xg);
    const StencilOffsets<Dim> d(w, xg, grid.dx);
    std::vector<std::pair<std::size_t, double>> by_node, by_flat;
    std::vector<double> dist_node, dist_flat;
    for_each_stencil_node<Dim>(w, [&](const IVec<Dim>& off, double wt) {
      const IVec<Dim> node = w.base() + off;
      by_node.emplace_back(grid.flat(node), wt);
      for (int a = 0; a < Dim; ++a)
        dist_node.push_back(((node.template cast<double>() - xg) * grid.dx)[a]);
    });
    for_each_stencil_node<Dim>(w, grid.flat(w.base()), stride,
                               [&](const IVec<Dim>& off, std::size_t f, double wt) {
      by_flat.emplace_back(f, wt);
      for (int a = 0; a < Dim; ++a) dist_flat.push_back(d.d[a][off[a]]);
    });
    ASSERT_EQ(by_node, by_flat) << "trial " << trial;
    ASSERT_EQ(dist_node, dist_flat) << "trial " << trial;  // bit for bit
  }
}

TEST(BSpline, FlatIndexStencilVisitsTheSameNodesWithTheSameWeightsAndDistances) {
  std::mt19937_64 rng(11);
  check_flat_stencil<2>(rng);
  check_flat_stencil<3>(rng);
}

// AffineTerms gives every node of a stencil the double that P2G's per-node product
// affine * (node − x/dx)·dx gave before it (the results of every study were computed so), in
// the project's build (no FMA); with -march=native the compiler may fuse either side's
// multiply-adds, so there the two agree to round-off only. A change of Eigen's evaluation
// order, or of the summation order in AffineTerms::at, fails here.
template <int Dim>
void check_affine_terms(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double dx = 10.0;
  int differ = 0;
  for (int trial = 0; trial < 50000; ++trial) {
    Mat<Dim> a;
    Vec<Dim> xg;
    for (int i = 0; i < Dim * Dim; ++i) a.data()[i] = 1e6 * u(rng);
    for (int i = 0; i < Dim; ++i) xg[i] = 300.0 * u(rng);
    const StencilWeights<Dim> w(xg);
    const AffineTerms<Dim> terms(a, StencilOffsets<Dim>(w, xg, dx));
    for_each_stencil_node<Dim>(w, [&](const IVec<Dim>& off, double) {
      const Vec<Dim> dpos = ((w.base() + off).template cast<double>() - xg) * dx;
      const Vec<Dim> eigen = a * dpos;
      const Vec<Dim> ours = terms.at(off);
      for (int i = 0; i < Dim; ++i) {
        ASSERT_NEAR(ours[i], eigen[i], 1e-12 * (a.row(i).cwiseAbs() * dpos.cwiseAbs()).sum());
        differ += ours[i] != eigen[i];
      }
    });
  }
#ifndef __FMA__
  EXPECT_EQ(differ, 0) << Dim << "D: components that differ from affine * Δx in the last bits";
#endif
}

TEST(BSpline, AffineTermsAreTheAffineProductOfEveryNodeToTheBit) {
  std::mt19937_64 rng(13);
  check_affine_terms<2>(rng);
  check_affine_terms<3>(rng);
}

// gather_apic against the textbook sums v = Σ w v_i and B = Σ w v_i Δxᵀ (Δx = node − particle),
// computed node by node with Eigen, on a random velocity field; and, for an affine field
// v(x) = v0 + G x, the APIC identities v = v(x_p) and 4/dx²·B = G (quadratic B-splines
// reproduce linear fields; Jiang et al. 2015).
template <int Dim>
void check_gather(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Grid<Dim> grid = test_grid<Dim>(2.0, -12, 25);  // covers every stencil of |x/dx| ≤ 8
  Mat<Dim> g;
  for (int i = 0; i < Dim * Dim; ++i) g.data()[i] = u(rng);
  const Vec<Dim> v0 = Vec<Dim>::Random();
  for (int trial = 0; trial < 500; ++trial) {
    Vec<Dim> xg;
    for (int a = 0; a < Dim; ++a) xg[a] = 8.0 * u(rng);
    const StencilWeights<Dim> w(xg);
    const StencilOffsets<Dim> d(w, xg, grid.dx);
    // A random field: the same sums node by node.
    for (auto& node : grid.nodes) node.vel = Vec<Dim>::Random();
    Vec<Dim> v_ref = Vec<Dim>::Zero();
    Mat<Dim> b_ref = Mat<Dim>::Zero();
    for_each_stencil_node<Dim>(w, [&](const IVec<Dim>& off, double wt) {
      const IVec<Dim> node = w.base() + off;
      const Vec<Dim>& vi = grid.nodes[grid.flat(node)].vel;
      v_ref += wt * vi;
      b_ref += wt * vi * ((node.template cast<double>() - xg) * grid.dx).transpose();
    });
    Vec<Dim> v;
    Mat<Dim> b;
    const auto vel = [&](std::size_t f) -> const Vec<Dim>& { return grid.nodes[f].vel; };
    gather_apic<Dim>(w, d, grid.flat(w.base()), grid.strides(), vel, v, b);
    ASSERT_LT((v - v_ref).norm(), kRoundOff) << "trial " << trial;
    ASSERT_LT((b - b_ref).norm(), kRoundOff * grid.dx) << "trial " << trial;
    // An affine field is gathered exactly.
    for (std::size_t f = 0; f < grid.nodes.size(); ++f)
      grid.nodes[f].vel = v0 + g * grid.position(grid.node_of(f));
    gather_apic<Dim>(w, d, grid.flat(w.base()), grid.strides(), vel, v, b);
    ASSERT_LT((v - (v0 + g * (xg * grid.dx))).norm(), kRoundOff * 100.0) << "trial " << trial;
    ASSERT_LT((4.0 / (grid.dx * grid.dx) * b - g).norm(), kRoundOff) << "trial " << trial;
  }
}

TEST(BSpline, GatherApicSumsTheStencilAndReproducesAffineVelocityFields) {
  std::mt19937_64 rng(17);
  check_gather<2>(rng);
  check_gather<3>(rng);
}

}  // namespace
}  // namespace crevasse
