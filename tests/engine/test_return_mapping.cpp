// Capped von Mises return mapping in principal Hencky strain (engine/capped_von_mises.hpp),
// checked against the definition of the yield surface (docs/model.md) rather than against stored
// numbers: admissibility of every returned state, exact volume preservation of the shear
// return, the implicit cap return landing on p_c(ε_v^p + Δ), monotone ε_v^p, and a stable
// return when the softening is steeper than the elastic unloading (cζ ≥ K, local snap-back),
// where the root is still unique because g is convex.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "engine/capped_von_mises.hpp"
#include "engine/hencky.hpp"

namespace crevasse {
namespace {

const ElasticModuli kModuli = ElasticModuli::from_young_poisson(1.0e9, 0.3);

template <int Dim>
struct Invariants {
  double p, q;
};

template <int Dim>
Invariants<Dim> invariants(const Vec<Dim>& eps) {
  const Vec<Dim> tau = principal_kirchhoff<Dim>(kModuli, eps);
  const double p = -tau.sum() / Dim;
  const Vec<Dim> dev = tau.array() + p;
  return {p, std::sqrt(1.5) * dev.norm()};
}

CappedVonMisesParams params(double c, double zeta, double qy) {
  CappedVonMisesParams p;
  p.tensile_strength_c = c;
  p.softening_zeta = zeta;
  p.shear_strength_qy = qy;
  return p;
}

// Round-off of the returned state: strains of up to 5e-2 times moduli of 1e9 give stresses of
// 5e7 Pa known to ~1e-16 relative, i.e. ~1e-8 Pa; the Newton solve of the cap stops at 1e-15
// relative in Δ. 1e-9 relative to c (≥ 1e5 Pa) is 1e-4 Pa: tight, yet far above round-off.
constexpr double kYieldTol = 1e-9;

// Random principal trial strains: a volumetric part (tension or compression) plus a deviator,
// from elastic to far past both surfaces (|ε| up to 2e-2, 20 times the strain of q_y = 10 MPa).
template <int Dim>
Vec<Dim> random_trial(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> vol(-1.0e-2, 2.0e-2), dev(-1.0e-2, 1.0e-2);
  std::uniform_int_distribution<int> scale_pick(0, 3);
  const double scales[] = {1e-4, 1e-3, 1e-2, 1.0};  // many states near the surfaces too
  const double s = scales[scale_pick(rng)];
  Vec<Dim> e;
  const double v = vol(rng) * s;
  for (int a = 0; a < Dim; ++a) e[a] = v + dev(rng) * s;
  return e;
}

struct MaterialCase {
  double c, zeta, qy;
};

// Several strengths and softening rates, all with ζ < K/c (implicit cap): K ≈ 0.83–0.96 GPa.
const MaterialCase kImplicitCases[] = {
    {1.0e6, 0.0, 1.0e7},    {1.0e6, 50.0, 1.0e7},  {1.0e6, 500.0, 1.0e7},
    {1.0e5, 5000.0, 1.0e6}, {5.0e6, 100.0, 2.0e6}, {2.0e5, 10.0, 5.0e5},
};

template <int Dim>
void check_admissible_and_exact(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> eps0(0.0, 2.0e-2);
  const double k = kModuli.bulk(Dim);
  int cap_cases = 0, shear_only_cases = 0;
  for (const MaterialCase& mc : kImplicitCases) {
    const CappedVonMisesParams pr = params(mc.c, mc.zeta, mc.qy);
    ASSERT_LT(mc.c * mc.zeta, k) << "the implicit cases need ζ < K/c";
    for (int trial = 0; trial < 4000; ++trial) {
      const Vec<Dim> eps_tr = random_trial<Dim>(rng);
      const double eps_v_p = trial % 3 == 0 ? 0.0 : eps0(rng);
      const ReturnResult<Dim> r = return_map_capped_von_mises<Dim>(eps_tr, eps_v_p, kModuli, pr);
      const Invariants<Dim> tr = invariants<Dim>(eps_tr), out = invariants<Dim>(r.eps);
      const double eps_new = eps_v_p + r.delta_eps_v;
      const double pc_new = cap_pressure(pr, eps_new);
      // ε_v^p never decreases, and nothing happens inside the elastic domain.
      EXPECT_GE(r.delta_eps_v, 0.0);
      // Φ ≤ 0 on both branches, with the strength at the end-of-step opening.
      EXPECT_GE(out.p - pc_new, -kYieldTol * mc.c) << "cap violated";
      EXPECT_LE(out.q - shear_strength(pr, eps_new, out.p), kYieldTol * mc.c) << "shear violated";
      // The deviator is only ever scaled, never rotated or grown (radial return). Round-off:
      // removing the trace costs ~1e-16·|ε| absolute, whatever the size of the deviator.
      const double roundoff = 1e-14 * eps_tr.norm();
      const Vec<Dim> dev_tr = eps_tr.array() - eps_tr.sum() / Dim;
      const Vec<Dim> dev_out = r.eps.array() - r.eps.sum() / Dim;
      EXPECT_LE(dev_out.norm(), dev_tr.norm() + roundoff);
      EXPECT_NEAR((dev_out - dev_tr * (dev_out.norm() / std::max(dev_tr.norm(), 1e-300))).norm(),
                  0.0, roundoff);
      if (r.cap_active) {
        ++cap_cases;
        // The cap was violated, and the implicit return lands on p_c(ε_v^p + Δ).
        EXPECT_LT(tr.p, cap_pressure(pr, eps_v_p));
        EXPECT_NEAR(out.p, pc_new, kYieldTol * mc.c);
        // The cap shifts the trace by exactly −Δ.
        EXPECT_NEAR(r.eps.sum(), eps_tr.sum() - r.delta_eps_v, 1e-15);
      } else {
        EXPECT_EQ(r.delta_eps_v, 0.0);
        EXPECT_GE(tr.p, cap_pressure(pr, eps_v_p));
      }
      if (r.shear_active && !r.cap_active) {
        ++shear_only_cases;
        // Isochoric: the trace is untouched (bit-for-bit up to the add/subtract of tr/d).
        EXPECT_NEAR(r.eps.sum(), eps_tr.sum(), 1e-16 * Dim + 1e-15 * std::abs(eps_tr.sum()));
        // Returned exactly onto the cylinder.
        EXPECT_NEAR(out.q, shear_strength(pr, eps_new, out.p), kYieldTol * mc.c);
      }
      if (!r.cap_active && !r.shear_active) {
        EXPECT_EQ(r.eps, eps_tr);
      }
    }
  }
  // The random states exercise both branches many times (no vacuous pass).
  EXPECT_GT(cap_cases, 1000);
  EXPECT_GT(shear_only_cases, 1000);
}

TEST(ReturnMapping, ReturnedStatesAreAdmissibleAndOnTheSurface2d) {
  check_admissible_and_exact<2>(101);
}
TEST(ReturnMapping, ReturnedStatesAreAdmissibleAndOnTheSurface3d) {
  check_admissible_and_exact<3>(202);
}

// Perfectly plastic cap (ζ = 0): the increment has the closed form Δ = (p_c − p_tr)/K with
// p_c = −c, and the returned pressure is exactly −c.
TEST(ReturnMapping, PerfectlyPlasticCapHasClosedForm) {
  const CappedVonMisesParams pr = params(1.0e6, 0.0, 1.0e9);
  const double k = kModuli.bulk(3);
  const Vec<3> eps_tr(3e-3, 2e-3, 1e-3);
  const double p_tr = -k * eps_tr.sum();
  const ReturnResult<3> r = return_map_capped_von_mises<3>(eps_tr, 0.0, kModuli, pr);
  ASSERT_TRUE(r.cap_active);
  EXPECT_NEAR(r.delta_eps_v, (-1.0e6 - p_tr) / k, 1e-15);  // Δ ≈ 5e-3: 1e-15 is round-off
  EXPECT_NEAR(invariants<3>(r.eps).p, -1.0e6, 1e-9 * 1.0e6);
}

// Along random strain paths, ε_v^p never decreases and every state stays admissible: the
// return is applied to the previous returned state plus a random increment, as in a run.
template <int Dim>
void check_strain_paths(double zeta, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> inc(0.0, 3e-4);
  std::uniform_real_distribution<double> bias(-1e-4, 3e-4);  // drift towards tension
  const double c = 1.0e6;
  const CappedVonMisesParams pr = params(c, zeta, 1.0e7);
  const double k = kModuli.bulk(Dim);
  const bool implicit = c * zeta < k;
  for (int path = 0; path < 50; ++path) {
    Vec<Dim> eps = Vec<Dim>::Zero();
    double eps_v_p = 0.0;
    const double drift = bias(rng);
    for (int n = 0; n < 400; ++n) {
      Vec<Dim> trial = eps;
      for (int a = 0; a < Dim; ++a) trial[a] += drift + inc(rng);
      const ReturnResult<Dim> r = return_map_capped_von_mises<Dim>(trial, eps_v_p, kModuli, pr);
      ASSERT_GE(r.delta_eps_v, 0.0);
      ASSERT_TRUE(r.eps.allFinite());
      // Implicit: admissible at the end-of-step opening. Explicit: the cap is taken at the
      // start-of-step opening, so that is the surface it must respect.
      const double pc = cap_pressure(pr, implicit ? eps_v_p + r.delta_eps_v : eps_v_p);
      const Invariants<Dim> out = invariants<Dim>(r.eps);
      ASSERT_GE(out.p - pc, -kYieldTol * c) << "path " << path << " step " << n;
      // The tension a softening material carries never exceeds its intact strength.
      ASSERT_GE(out.p, -c * (1.0 + kYieldTol));
      eps_v_p += r.delta_eps_v;
      eps = r.eps;
    }
  }
}

TEST(ReturnMapping, PlasticOpeningNeverDecreasesImplicit2d) { check_strain_paths<2>(500.0, 5); }
TEST(ReturnMapping, PlasticOpeningNeverDecreasesImplicit3d) { check_strain_paths<3>(500.0, 6); }
TEST(ReturnMapping, PlasticOpeningNeverDecreasesSnapBack2d) { check_strain_paths<2>(5000.0, 7); }
TEST(ReturnMapping, PlasticOpeningNeverDecreasesSnapBack3d) { check_strain_paths<3>(5000.0, 8); }

// The implicit increment solves g(Δ) = p_tr + KΔ + c·exp(−ζ(ε_v^p + Δ)) = 0 inside the bracket
// [0, −p_tr/K], including near ζ → K/c where g' → 0 at Δ = 0, and past it (cζ/K = 2, 10, 100:
// g first decreases, but it is convex and negative at 0, so it crosses zero once).
// Opened ice (strength gone: ε_v^p = 20/ζ, e^{−20} of it left) keeps no tension, neither
// through its mean stress (the cap) nor through its deviator: for any trial strain the largest
// principal Kirchhoff stress after the return is at most e^{−20}(c + q_y) — nil. With the literal
// law (q_y kept by damaged ice) the same trials carry tensions of the order of q_y, which is
// what blew up a free glacier; the test checks that too, so it would fail if softening the shear
// strength stopped reaching the return. Residual friction only acts under compression (M·p with
// p > 0), where σ_1 = −p + q/√3 stays compressive for M < √3, so it keeps the property.
template <int Dim>
void check_opened_ice_keeps_no_tension() {
  const double c = 3.6e5, zeta = 500.0, qy = 3.6e6;
  const double opened = 20.0 / zeta;
  std::mt19937 rng(4242);
  std::uniform_real_distribution<double> strain(-2e-3, 2e-3);
  for (double m_residual : {0.0, 1.2}) {
    CappedVonMisesParams soft = params(c, zeta, qy);
    soft.residual_friction_m = m_residual;
    CappedVonMisesParams literal = soft;
    literal.damage_softens_shear = false;
    double literal_max = 0.0;
    for (int trial = 0; trial < 2000; ++trial) {
      Vec<Dim> eps;
      for (int a = 0; a < Dim; ++a) eps[a] = strain(rng);
      const auto r = return_map_capped_von_mises<Dim>(eps, opened, kModuli, soft);
      const double tension = principal_kirchhoff<Dim>(kModuli, r.eps).maxCoeff();
      ASSERT_LE(tension, 1e-6 * c) << "trial " << trial << " M = " << m_residual;
      const auto l = return_map_capped_von_mises<Dim>(eps, opened, kModuli, literal);
      literal_max = std::max(literal_max, principal_kirchhoff<Dim>(kModuli, l.eps).maxCoeff());
    }
    EXPECT_GT(literal_max, 0.5 * qy / std::sqrt(3.0)) << "M = " << m_residual;
  }
}
TEST(ReturnMapping, OpenedIceKeepsNoTensionThroughItsDeviator2d) { check_opened_ice_keeps_no_tension<2>(); }
TEST(ReturnMapping, OpenedIceKeepsNoTensionThroughItsDeviator3d) { check_opened_ice_keeps_no_tension<3>(); }

TEST(ReturnMapping, ImplicitCapIncrementSolvesTheConsistencyEquation) {
  const double k = kModuli.bulk(2);
  for (const double frac : {0.01, 0.3, 0.9, 0.999, 2.0, 10.0, 100.0}) {
    const double c = 1.0e6;
    const CappedVonMisesParams pr = params(c, frac * k / c, 1.0e7);
    for (const double eps_v_p : {0.0, 1e-4, 1e-3}) {
      for (const double over : {1e-6, 1e-3, 0.5, 10.0}) {
        const double p_tr = cap_pressure(pr, eps_v_p) * (1.0 + over);
        const double d = cap_return_increment(p_tr, k, eps_v_p, pr);
        const double g = p_tr + k * d + c * std::exp(-pr.softening_zeta * (eps_v_p + d));
        EXPECT_GE(d, 0.0);
        EXPECT_LE(d, -p_tr / k * (1.0 + 1e-15));
        // Residual relative to the terms it balances (|p_tr|): Newton to 1e-15 in Δ, i.e. an
        // absolute floor K·1e-15 ≈ 1e-6 Pa that matters only for the softest caps (|p_tr| ~ 1e2 Pa).
        EXPECT_NEAR(g, 0.0, 1e-9 * std::abs(p_tr) + 1e-15 * k)
            << "ζc/K " << frac << " over " << over;
      }
    }
  }
}

// Snap-back range (cζ = 10 K): a bar of ice stretched in uniaxial volumetric tension with steps
// from small (1e-6, a thousandth of the yield strain c/K) to enormous (0.1). Stability: the
// pressure stays in [−c, 0] — never more tension than intact ice carries, never compression from an
// overshooting return — it is exactly the softened cap p_c(ε_v^p + Δ) (the yield condition holds
// at the end of the step), it rises monotonically to 0 as the material opens, and ε_v^p grows
// without blowing up (each increment is bounded by the trial stretch).
template <int Dim>
void check_snap_back_stable(double step) {
  const double c = 1.0e6;
  const double k = kModuli.bulk(Dim);
  const CappedVonMisesParams pr = params(c, 10.0 * k / c, 1.0e12);
  Vec<Dim> eps = Vec<Dim>::Zero();
  double eps_v_p = 0.0;
  double last_p = -c;
  bool yielded = false;
  for (int n = 0; n < 5000; ++n) {
    const Vec<Dim> trial = eps.array() + step / Dim;
    const double p_tr = invariants<Dim>(trial).p;
    const ReturnResult<Dim> r = return_map_capped_von_mises<Dim>(trial, eps_v_p, kModuli, pr);
    const double p = invariants<Dim>(r.eps).p;
    ASSERT_GE(r.delta_eps_v, 0.0);
    ASSERT_LE(r.delta_eps_v, -p_tr / k * (1.0 + 1e-12) + 1e-300);
    ASSERT_GE(p, -c * (1.0 + kYieldTol));
    ASSERT_LE(p, kYieldTol * c);
    if (r.cap_active) {
      EXPECT_NEAR(p, cap_pressure(pr, eps_v_p + r.delta_eps_v), kYieldTol * c);  // on the cap
      if (yielded) {
        EXPECT_GE(p, last_p - kYieldTol * c);  // softening is monotone
      }
      yielded = true;
      last_p = p;
    }
    eps_v_p += r.delta_eps_v;
    eps = r.eps;
  }
  EXPECT_TRUE(yielded);
  // Fully opened: the strength is gone (the cap is at e^{−ζ ε_v^p} c, ζ ε_v^p large).
  EXPECT_LT(std::abs(invariants<Dim>(eps).p), 1e-3 * c);
}

TEST(ReturnMapping, SnapBackSofteningIsStable2d) {
  for (const double step : {1e-6, 1e-5, 1e-3, 1e-1}) check_snap_back_stable<2>(step);
}
TEST(ReturnMapping, SnapBackSofteningIsStable3d) {
  for (const double step : {1e-6, 1e-5, 1e-3, 1e-1}) check_snap_back_stable<3>(step);
}

// The brittle cap: a state past the cap keeps no elastic strain (no stress, shear included) and
// its whole trial trace becomes opening; a state inside the cap is returned as before.
TEST(ReturnMapping, BrittleCapDropsTheWholeStress) {
  const ElasticModuli m = ElasticModuli::from_young_poisson(1e9, 0.3);
  CappedVonMisesParams p;
  p.tensile_strength_c = 1e5;
  p.shear_strength_qy = 1e6;
  p.softening_zeta = 500.0;
  p.brittle_cap = true;
  const Vec<2> past(2.0e-4, 1.5e-4);  // p = −K·3.5e-4 ≈ −0.34 MPa, past −c
  const auto r = return_map_capped_von_mises<2>(past, 0.0, m, p);
  EXPECT_TRUE(r.cap_active);
  EXPECT_EQ(r.eps, Vec<2>::Zero());
  EXPECT_DOUBLE_EQ(r.delta_eps_v, past.sum());
  const Vec<2> inside(2.0e-5, -1.0e-5);
  p.brittle_cap = false;
  const auto plain = return_map_capped_von_mises<2>(inside, 0.0, m, p);
  p.brittle_cap = true;
  const auto brittle = return_map_capped_von_mises<2>(inside, 0.0, m, p);
  EXPECT_EQ(brittle.eps, plain.eps);
  EXPECT_FALSE(brittle.cap_active);
}

}  // namespace
}  // namespace crevasse
