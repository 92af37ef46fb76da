// The 2D closed-form principal Hencky strain and frame (engine/hencky.hpp, principal_hencky<2>)
// and the 2D Kirchhoff stress built from them, against
//  * a long-double reference: b − I formed from H = F − I and Eigen's iterative
//    SelfAdjointEigenSolver in long double (64-bit mantissa, unit round-off 5.4e-20), and for
//    nearly singular F the volume identity ε₀ = log|det F| − ε₁ in long double;
//  * Eigen in double, as the engine used it before (computeDirect of F Fᵀ − I), its iterative
//    solver, and JacobiSVD of F (ε = log σ);
// on random deformation gradients (near-identity, moderate, large stretch) and degenerate ones
// (identity, equal stretches, pure rotation, near-isotropic, nearly singular, reflected).
//
// Tolerances, with u = 2^-53 ≈ 1.1e-16, σ₀ ≤ σ₁ the singular values of F and
// β = max(1, σ₁²) the size of the terms that b − I is summed from:
//  * closed form vs reference: the entries of b − I carry a few u·β absolute (only a few u
//    relative to ‖b − I‖ when F − I is itself small), its eigenvalues the same (Weyl), and
//    ε₁ = ½ log(1 + λ₁) divides that by 2σ₁²; det F − 1 carries a few u·β, so
//    ε₀ = log|det F| − ε₁ a few u·β/(σ₀σ₁). With K = β/(σ₀σ₁) (≥ σ₁/σ₀, ≥ 1; the conditioning
//    of any solve through b − I; K ≈ 1 for ice), the bound is 1e-12‖ε‖∞ (the accuracy the engine
//    asks for) + 16 u K (observed: ~2e-16 relative near the identity).
//  * Eigen's direct solver forms F Fᵀ − I and takes ε₀ from 1 + λ₀ = σ₀², so its ε₀ is good only
//    to ~2u·β/σ₀²: the comparison allows 16 u β/σ₀² plus the above.
//  * JacobiSVD's σ_i are good to ~u σ₁ (normwise), so log σ_i to ~u σ₁/σ_i: 16 u σ₁/σ₀.
//  * U: orthonormal and det U = +1 to 8u; the eigen-projector u uᵀ of the larger eigenvalue
//    agrees with the reference's to 16 u β/gap + 1e-14 (Davis–Kahan), checked when the gap is
//    not negligible.
//  * The rebuilt U diag(e^{2ε} − 1) Uᵀ reproduces b − I to 16 u β plus the error of ε times ‖b‖
//    (backward error).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "engine/hencky.hpp"

namespace crevasse {
namespace {

constexpr double kU = std::numeric_limits<double>::epsilon() / 2;  // unit round-off 1.1e-16
using Mat2L = Eigen::Matrix<long double, 2, 2>;
using Vec2L = Eigen::Matrix<long double, 2, 1>;

Mat<2> rotation(double theta) {
  Mat<2> r;
  r << std::cos(theta), -std::sin(theta), std::sin(theta), std::cos(theta);
  return r;
}

// F = R(θ) diag(σ₀, σ₁) R(φ)ᵀ, rounded to double (the tests use the rounded F as the input).
Mat<2> make_f(double s0, double s1, double theta, double phi) {
  return rotation(theta) * Vec<2>(s0, s1).asDiagonal() * rotation(phi).transpose();
}

struct Reference {
  Vec2L eps;      // ascending
  Vec2L u_big;    // unit eigenvector of the larger eigenvalue of b
  long double norm_a;  // ‖b − I‖₂ = max |λ_i|
  long double gap;     // λ₁ − λ₀
  long double kappa;   // σ₁/σ₀ of F
  long double norm_b;  // ‖b‖₂ = σ₁²
  long double beta;    // max(1, σ₁²)
  long double k_cond;  // K = β/(σ₀σ₁)
};

Reference reference(const Mat<2>& F) {
  const Mat2L f = F.cast<long double>();
  const Mat2L h = f - Mat2L::Identity();  // exact: F − I is exact in double already
  Mat2L a = h + h.transpose() + h * h.transpose();
  a(1, 0) = a(0, 1);
  Eigen::SelfAdjointEigenSolver<Mat2L> eig(a);  // iterative QR, long double
  const Vec2L lam = eig.eigenvalues();
  Reference r;
  r.norm_a = std::max(std::abs(lam[0]), std::abs(lam[1]));
  r.gap = lam[1] - lam[0];
  r.u_big = eig.eigenvectors().col(1);
  r.eps[1] = 0.5L * std::log1p(lam[1]);
  const long double det = f(0, 0) * f(1, 1) - f(0, 1) * f(1, 0);
  // 1 + λ₀ = σ₀² is accurate to ~5e-20‖b‖ absolute; once σ₀² < 1e-3‖b‖ (κ > 30) take
  // ε₀ = log(σ₀σ₁) − ε₁ with det F in long double instead (relative error ~5e-20 κ).
  if (1.0L + lam[0] > 1e-3L * (1.0L + lam[1])) {
    r.eps[0] = 0.5L * std::log1p(lam[0]);
  } else {
    r.eps[0] = std::log(std::abs(det)) - r.eps[1];
  }
  r.norm_b = 1.0L + lam[1];
  r.kappa = std::exp(r.eps[1] - r.eps[0]);
  r.beta = std::max(1.0L, r.norm_b);
  r.k_cond = r.beta / std::exp(r.eps[0] + r.eps[1]);
  return r;
}

double inf_norm(const Vec<2>& v) { return v.cwiseAbs().maxCoeff(); }

// Largest error of ε seen, absolute and as a fraction of its tolerance (printed by the tests).
struct Worst {
  double abs = 0.0, rel = 0.0, of_tol = 0.0;
};

// Checks one F against the reference; returns the errors of ε (for reporting).
Worst check_against_reference(const Mat<2>& F, const char* what) {
  SCOPED_TRACE(what);
  const PrincipalStretch<2> s = principal_hencky<2>(F);
  const Reference ref = reference(F);
  const Vec<2> eps_ref = ref.eps.cast<double>();
  const double scale = inf_norm(eps_ref);
  const double k_cond = static_cast<double>(ref.k_cond);
  const double beta = static_cast<double>(ref.beta);
  const double tol = 1e-12 * scale + 16 * kU * k_cond;
  EXPECT_TRUE(s.eps.allFinite());
  EXPECT_NEAR(s.eps[0], eps_ref[0], tol) << "F =\n" << F;
  EXPECT_NEAR(s.eps[1], eps_ref[1], tol) << "F =\n" << F;

  // U is a proper rotation to round-off.
  EXPECT_LE((s.U.transpose() * s.U - Mat<2>::Identity()).cwiseAbs().maxCoeff(), 8 * kU);
  EXPECT_NEAR(s.U.determinant(), 1.0, 8 * kU);

  // Eigen-projector of the larger eigenvalue, when the gap makes it well defined.
  const double norm_a = static_cast<double>(ref.norm_a);
  const double gap = static_cast<double>(ref.gap);
  if (gap > 1e-6 * norm_a && gap > 0.0) {
    const Vec<2> u = s.U.col(1);
    const Vec<2> v = ref.u_big.cast<double>();
    const double proj_err = (u * u.transpose() - v * v.transpose()).cwiseAbs().maxCoeff();
    EXPECT_LE(proj_err, 16 * kU * beta / gap + 1e-14) << "F =\n" << F;
  }

  // Backward error: U diag(σ²) Uᵀ = b, i.e. U diag(expm1(2ε)) Uᵀ = b − I.
  const Mat2L ul = s.U.cast<long double>();
  Vec2L lam;
  for (int i = 0; i < 2; ++i) lam[i] = std::expm1(2.0L * static_cast<long double>(s.eps[i]));
  const Mat2L fl = F.cast<long double>();
  const Mat2L a_ref = fl * fl.transpose() - Mat2L::Identity();
  const Mat2L a_rebuilt = ul * lam.asDiagonal() * ul.transpose();
  const double back_err = static_cast<double>((a_rebuilt - a_ref).cwiseAbs().maxCoeff());
  // A relative error δ of σ_i² = e^{2ε_i} is δσ_i² absolute; δ ≤ 2·tol above.
  const double lam_tol = 16 * kU * beta + 2 * tol * static_cast<double>(ref.norm_b);
  EXPECT_LE(back_err, lam_tol) << "F =\n" << F;
  Worst w;
  w.abs = inf_norm(s.eps - eps_ref);
  w.rel = scale > 0 ? w.abs / scale : w.abs;
  w.of_tol = w.abs / tol;
  return w;
}

void keep_worst(Worst& acc, const Worst& w) {
  acc.abs = std::max(acc.abs, w.abs);
  acc.rel = std::max(acc.rel, w.rel);
  acc.of_tol = std::max(acc.of_tol, w.of_tol);
}

// Eigen in double: the engine's previous path (computeDirect of F Fᵀ − I), the iterative
// solver, and JacobiSVD. Only for F far enough from singular that F Fᵀ − I keeps σ_min².
void check_against_eigen(const Mat<2>& F, const char* what) {
  SCOPED_TRACE(what);
  const PrincipalStretch<2> s = principal_hencky<2>(F);
  const Reference ref = reference(F);
  const double kappa = static_cast<double>(ref.kappa);
  const double beta = static_cast<double>(ref.beta);
  const double sigma_min2 = std::exp(2.0 * static_cast<double>(ref.eps[0]));
  const double scale = inf_norm(ref.eps.cast<double>());
  const double own = 1e-12 * scale + 16 * kU * static_cast<double>(ref.k_cond);

  const Mat<2> b_minus_i = F * F.transpose() - Mat<2>::Identity();
  const double eigen_tol = own + 16 * kU * beta / sigma_min2;
  Eigen::SelfAdjointEigenSolver<Mat<2>> direct;
  direct.computeDirect(b_minus_i);
  Eigen::SelfAdjointEigenSolver<Mat<2>> iterative(b_minus_i);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(s.eps[i], 0.5 * std::log1p(direct.eigenvalues()[i]), eigen_tol) << "F =\n" << F;
    EXPECT_NEAR(s.eps[i], 0.5 * std::log1p(iterative.eigenvalues()[i]), eigen_tol) << "F =\n" << F;
  }

  Eigen::JacobiSVD<Mat<2>> svd(F);
  const Vec<2> sv = svd.singularValues();  // descending
  EXPECT_NEAR(s.eps[1], std::log(sv[0]), own + 16 * kU * kappa) << "F =\n" << F;
  EXPECT_NEAR(s.eps[0], std::log(sv[1]), own + 16 * kU * kappa) << "F =\n" << F;
}

// The 2D Kirchhoff stress τ₀ I + (τ₁ − τ₀) u uᵀ against U diag(τ_i) Uᵀ in long double.
void check_stress(const Mat<2>& F, const ElasticModuli& m) {
  const PrincipalStretch<2> s = principal_hencky<2>(F);
  const Mat<2> tau = kirchhoff_stress<2>(m, s);
  const Vec<2> t = principal_kirchhoff<2>(m, s.eps);
  const Mat2L ul = s.U.cast<long double>();
  const Mat2L tau_ref = ul * t.cast<long double>().asDiagonal() * ul.transpose();
  const double err = static_cast<double>((tau.cast<long double>() - tau_ref).cwiseAbs().maxCoeff());
  EXPECT_LE(err, 8 * kU * inf_norm(t) + 1e-300) << "F =\n" << F;
  EXPECT_EQ(tau(0, 1), tau(1, 0));
}

const ElasticModuli kModuli = ElasticModuli::from_young_poisson(1.0e9, 0.3);

TEST(PrincipalHencky2D, RandomNearIdentityStrainsOfIce) {
  // |ε| from 1e-9 to 1e-1 in random frames. With a rotation in F (θ ≠ φ), F − I is O(1) and
  // b − I = F Fᵀ − I cancels to ‖ε‖ whatever the formula, so ε is good to a few u absolute (the
  // tolerance's 16 u κ term). Without one (F = R S Rᵀ, F − I ~ ε), b − I is formed with relative
  // precision and ε is good to a few u relative even at |ε| = 1e-9 (F Fᵀ − I would give 1e-7).
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), unit(-1.0, 1.0), expo(-9.0, -1.0);
  Worst stretch, rotated;
  for (int k = 0; k < 20000; ++k) {
    const double mag = std::pow(10.0, expo(rng));
    const double th = angle(rng);
    const double ph = k % 2 ? th : angle(rng);
    const Mat<2> F = make_f(std::exp(mag * unit(rng)), std::exp(mag * unit(rng)), th, ph);
    keep_worst(k % 2 ? stretch : rotated, check_against_reference(F, "near identity"));
    if (mag > 1e-6) check_against_eigen(F, "near identity");
    check_stress(F, kModuli);
    if (HasFailure()) break;
  }
  std::printf("near identity, pure stretch: worst error of eps %.1e relative, %.2f of tolerance\n",
              stretch.rel, stretch.of_tol);
  std::printf("near identity, rotated: worst error of eps %.1e absolute, %.2f of tolerance\n",
              rotated.abs, rotated.of_tol);
  EXPECT_LT(stretch.rel, 1e-13);
}

TEST(PrincipalHencky2D, RandomGeneralAndLargeStretch) {
  // Random F with entries in [−2, 2] around I, and stretches from 1e-3 to 1e3.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), entry(-2.0, 2.0), logs(-3.0, 3.0);
  Worst worst;
  for (int k = 0; k < 20000; ++k) {
    Mat<2> F;
    if (k % 2 == 0) {
      F << 1.0 + entry(rng), entry(rng), entry(rng), 1.0 + entry(rng);
      if (std::abs(F.determinant()) < 1e-3 * F.squaredNorm()) continue;  // near-singular: below
    } else {
      F = make_f(std::pow(10.0, logs(rng)), std::pow(10.0, logs(rng)), angle(rng), angle(rng));
    }
    keep_worst(worst, check_against_reference(F, "general"));
    check_against_eigen(F, "general");
    check_stress(F, kModuli);
    if (HasFailure()) break;
  }
  std::printf("general and large stretch: worst error of eps %.1e relative, %.2f of tolerance\n",
              worst.rel, worst.of_tol);
}

TEST(PrincipalHencky2D, Identity) {
  const PrincipalStretch<2> s = principal_hencky<2>(Mat<2>::Identity());
  EXPECT_EQ(s.eps[0], 0.0);
  EXPECT_EQ(s.eps[1], 0.0);
  EXPECT_EQ(s.U, Mat<2>::Identity());
  EXPECT_EQ(kirchhoff_stress<2>(kModuli, s), Mat<2>::Zero());
  check_against_reference(Mat<2>::Identity(), "identity");
  check_against_eigen(Mat<2>::Identity(), "identity");
}

TEST(PrincipalHencky2D, EqualStretchesAndNearIsotropic) {
  // s R(θ): both strains log s, any orthonormal U, isotropic stress. Then a spread of the two
  // stretches from 1e-15 to 1e-6 relative, where the frame is ill-conditioned but b is not.
  for (double st : {1.0 - 1e-3, 1.0 + 1e-3, 1.0 + 1e-9, 0.5, 3.0}) {
    for (double th : {0.0, 0.3, 1.7, -2.9}) {
      const Mat<2> F = st * rotation(th);
      const PrincipalStretch<2> s = principal_hencky<2>(F);
      const double e = std::log(st);
      EXPECT_NEAR(s.eps[0], e, 1e-14 * std::abs(e) + 4 * kU);
      EXPECT_NEAR(s.eps[1], e, 1e-14 * std::abs(e) + 4 * kU);
      // τ is isotropic to the error of ε times 2μ + 2λ (ε to 1e-14 relative + 4u).
      const Mat<2> tau = kirchhoff_stress<2>(kModuli, s);
      const double t = principal_kirchhoff<2>(kModuli, s.eps).cwiseAbs().maxCoeff();
      const double t_tol = 4e-14 * t + 16 * kU * (2 * kModuli.mu + 2 * kModuli.lambda);
      EXPECT_LE(std::abs(tau(0, 1)), t_tol);
      EXPECT_NEAR(tau(0, 0), tau(1, 1), t_tol);
      check_against_reference(F, "equal stretches");
      check_against_eigen(F, "equal stretches");
      check_stress(F, kModuli);
      for (double spread : {1e-15, 1e-12, 1e-9, 1e-6}) {
        const Mat<2> G = make_f(st, st * (1.0 + spread), th, 0.4);
        check_against_reference(G, "near isotropic");
        check_against_eigen(G, "near isotropic");
        check_stress(G, kModuli);
      }
    }
  }
  // Exactly diagonal, both orders (h > 0 and h < 0 branches, d = 0), and h = 0 with d ≠ 0.
  for (const Vec<2>& d : {Vec<2>(1.002, 0.999), Vec<2>(0.999, 1.002)}) {
    const Mat<2> F = d.asDiagonal();
    check_against_reference(F, "diagonal");
    const PrincipalStretch<2> s = principal_hencky<2>(F);
    EXPECT_NEAR(s.eps[0], std::log(d.minCoeff()), 1e-16);
    EXPECT_NEAR(s.eps[1], std::log(d.maxCoeff()), 1e-16);
  }
  check_against_reference(make_f(1.01, 0.99, M_PI / 4, 0.0), "h = 0");
}

TEST(PrincipalHencky2D, PureRotation) {
  for (double th = -3.1; th < 3.2; th += 0.1) {
    const Mat<2> F = rotation(th);
    const PrincipalStretch<2> s = principal_hencky<2>(F);
    // A rotation rounded to double is a stretch of at most a few u.
    EXPECT_LE(inf_norm(s.eps), 4 * kU);
    check_against_reference(F, "rotation");
    check_against_eigen(F, "rotation");
    // |τ| ≤ (2μ + 2λ)·4u: below 1e-5 Pa.
    EXPECT_LE(kirchhoff_stress<2>(kModuli, s).cwiseAbs().maxCoeff(), 1e-5);
  }
}

TEST(PrincipalHencky2D, NearlySingularStaysFiniteAndAccurate) {
  // σ_min from 1e-4 to 1e-12: ε₀ = log|det F| − ε₁ keeps ε₀ to ~u κ, where 1 + λ₀ from F Fᵀ − I
  // loses all digits once σ_min² < u (Eigen's direct solver then returns −inf or NaN).
  for (double smin : {1e-4, 1e-6, 1e-8, 1e-10, 1e-12}) {
    for (double th : {0.1, 1.2, -2.2}) {
      const Mat<2> F = make_f(1.0, smin, th, 0.7 * th);
      check_against_reference(F, "nearly singular");
      if (smin >= 1e-4) check_against_eigen(F, "nearly singular");
      const PrincipalStretch<2> s = principal_hencky<2>(F);
      EXPECT_TRUE(s.eps.allFinite());
      EXPECT_NEAR(s.eps[0], std::log(smin), 16 * kU / smin + 1e-12 * std::abs(std::log(smin)));
      check_stress(F, kModuli);
    }
  }
}

TEST(PrincipalHencky2D, ReflectionUsesAbsoluteDeterminant) {
  // det F < 0 (an inverted particle): b is still SPD and ε = log σ, as the eigen-solve of b gave.
  for (const Mat<2>& F : {Mat<2>(Vec<2>(-1.001, 0.999).asDiagonal()),
                          Mat<2>(make_f(1.2, 0.8, 0.3, 0.1) * Vec<2>(1.0, -1.0).asDiagonal()),
                          Mat<2>(make_f(3.0, 1e-3, 0.3, 0.1) * Vec<2>(-1.0, 1.0).asDiagonal())}) {
    check_against_reference(F, "reflection");
    check_against_eigen(F, "reflection");
  }
}

TEST(PrincipalHencky2D, RebuiltElasticGradientCarriesTheReturnedStrain) {
  // The return mapping's rebuild F_E' = U diag(e^{ε' − ε}) Uᵀ F_E (engine/particle_update.hpp, constitutive_update):
  // the principal strains of F_E' must be ε' and its frame U, to the same accuracy.
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), unit(-1.0, 1.0);
  for (int k = 0; k < 5000; ++k) {
    const double mag = k % 2 ? 1e-3 : 0.3;
    const Mat<2> F = make_f(std::exp(mag * unit(rng)), std::exp(mag * unit(rng)), angle(rng), angle(rng));
    const PrincipalStretch<2> s = principal_hencky<2>(F);
    // A returned state: a shift of the trace and a radial scaling of the deviator.
    const double tr = s.eps.sum();
    Vec<2> target = (s.eps.array() - tr / 2) * (0.5 + 0.5 * std::abs(unit(rng))) + tr / 2 - mag * 0.1 * std::abs(unit(rng));
    const Vec<2> scale = (target - s.eps).array().exp();
    const Mat<2> F2 = s.U * scale.asDiagonal() * s.U.transpose() * F;
    const PrincipalStretch<2> s2 = principal_hencky<2>(F2);
    std::sort(target.data(), target.data() + 2);
    const double tol = 1e-12 * inf_norm(target) + 32 * kU;
    EXPECT_NEAR(s2.eps[0], target[0], tol);
    EXPECT_NEAR(s2.eps[1], target[1], tol);
    // And Eigen (the engine's previous path) agrees with the rebuilt F_E' too.
    const Mat<2> b2 = F2 * F2.transpose() - Mat<2>::Identity();
    Eigen::SelfAdjointEigenSolver<Mat<2>> direct;
    direct.computeDirect(b2);
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(s2.eps[i], 0.5 * std::log1p(direct.eigenvalues()[i]), tol + 16 * kU);
    if (HasFailure()) break;
  }
}

}  // namespace
}  // namespace crevasse
