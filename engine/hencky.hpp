#pragma once
// Hencky (logarithmic-strain) elasticity. With the left stretch of F_E written b = F_E F_Eᵀ =
// U diag(Σ²) Uᵀ, the principal Hencky strains are ε = log Σ and the Kirchhoff stress is
// τ = U (2μ ε + λ tr(ε) I) Uᵀ (docs/model.md). Only the symmetric eigenproblem of b is needed,
// never a full SVD of F_E: returning ε → ε' maps F_E to U diag(exp(ε' − ε)) Uᵀ F_E.
#include <Eigen/Eigenvalues>
#include <cmath>

#include "engine/types.hpp"

namespace crevasse {

struct ElasticModuli {
  double mu = 0.0;      // shear modulus [Pa]
  double lambda = 0.0;  // first Lamé parameter [Pa]

  static ElasticModuli from_young_poisson(double youngs_modulus, double poisson_ratio) {
    ElasticModuli m;
    m.mu = youngs_modulus / (2.0 * (1.0 + poisson_ratio));
    m.lambda = youngs_modulus * poisson_ratio / ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
    return m;
  }
  // Bulk modulus in the d-dimensional convention of docs/model.md: p = −tr(τ)/d = −K_d tr(ε).
  double bulk(int dim) const { return lambda + 2.0 * mu / dim; }
  // P-wave modulus λ + 2μ, which sets the explicit time step.
  double p_wave_modulus() const { return lambda + 2.0 * mu; }
};

template <int Dim>
struct PrincipalStretch {
  Mat<Dim> U;          // eigenvectors of b (columns)
  Vec<Dim> eps;        // principal Hencky strains ε_i = ½ log(eigenvalue_i of b)
};

namespace detail {

// Below this spread of the eigenvalues of b − I (|λ₁ − λ₀|/2) the 2D closed form takes U = I.
// b − I is O(1) or smaller for ice, so the tensor it leaves out (at most 2e-150 in any entry)
// is far below the round-off of any entry of F; the bound only keeps r² and |v|² clear of
// underflow (r² > 1e-300 > the smallest normal double, 2.2e-308).
inline constexpr double kIsotropicSpread2 = 1e-150;

// 2D closed form (plane strain, F is 2×2). With H = F − I (exact for the entries of a
// deformation gradient near I), b − I = H + Hᵀ + H Hᵀ is formed entry by entry as
//   (b − I)₀₀ = H₀₀(2 + H₀₀) + F₀₁²,  (b − I)₁₁ = H₁₁(2 + H₁₁) + F₁₀²,  (b − I)₀₁ = F₀₀F₁₀ + F₀₁F₁₁,
// which keeps relative precision however small the strain (F Fᵀ − I loses digits to the 1).
// Eigenvalues of [[a, d], [d, c]]: m ± r with m = (a + c)/2, h = (a − c)/2, r = sqrt(h² + d²).
// The larger one's Hencky strain is ε₁ = ½ log1p(m + r); the other comes from the volume,
// ε₀ = log|det F| − ε₁ with det F − 1 = H₀₀ + H₁₁ + H₀₀H₁₁ − F₀₁F₁₀, which stays accurate when
// F is nearly singular (1 + λ₀ = σ₀² would lose everything below 1e-16) and makes
// ε₀ + ε₁ = log|det F| to round-off. The eigenvector of m + r is (h + r, d) when h ≥ 0 and
// (d, r − h) otherwise: both are exact null vectors of b − I − (m + r) I, and their length is at
// least r, so normalising cancels nothing. The other column is its rotation by −90°, so U is a
// proper rotation (det U = +1) and orthonormal to round-off; columns in ascending order of
// eigenvalue, as Eigen's solver returns them.
// The closed form in three parts, so that the engine's 2D update can run the arithmetic over a
// block of particles in vector registers and only the two logarithms one by one
// (engine/particle_update.hpp, update_particles_2d); principal_hencky_2d chains the same parts, so both give
// the same bits. Part 1: the entries of b − I, its half-trace m, half-spread h, off-diagonal d,
// r = sqrt(h² + d²) and |det F| − 1.
struct Hencky2dParts {
  double m, h, d, r, j_minus_1;
};
inline Hencky2dParts hencky_2d_parts(double f00, double f01, double f10, double f11) {
  const double h00 = f00 - 1.0, h11 = f11 - 1.0;
  const double a = h00 * (2.0 + h00) + f01 * f01;
  const double c = h11 * (2.0 + h11) + f10 * f10;
  Hencky2dParts q;
  q.d = f00 * f10 + f01 * f11;
  q.m = 0.5 * (a + c);
  q.h = 0.5 * (a - c);
  q.r = std::sqrt(q.h * q.h + q.d * q.d);
  const double j1 = h00 + h11 + (h00 * h11 - f01 * f10);
  q.j_minus_1 = j1 < -1.0 ? -2.0 - j1 : j1;  // det F < 0: |det F| − 1
  return q;
}
// Part 3: the unit eigenvector (ux, uy) of the larger eigenvalue (U's second column), without
// branches: both candidate vectors are formed and one is selected, and the isotropic case
// (r ≤ kIsotropicSpread2, U = I) is selected last, so a block of particles vectorises. The
// arithmetic of the selected lane is that of the branchy form.
// Returns whether the spread is resolved (U ≠ I).
inline bool hencky_2d_frame(const Hencky2dParts& q, double& ux, double& uy) {
  const bool pos = q.h >= 0.0;
  double vx = pos ? q.h + q.r : q.d;
  double vy = pos ? q.d : q.r - q.h;
  const double inv = 1.0 / std::sqrt(vx * vx + vy * vy);
  vx *= inv;
  vy *= inv;
  const bool spread = q.r > kIsotropicSpread2;
  ux = spread ? vx : 0.0;
  uy = spread ? vy : 1.0;
  return spread;
}
inline PrincipalStretch<2> principal_hencky_2d(const Mat<2>& F) {
  const Hencky2dParts q = hencky_2d_parts(F(0, 0), F(0, 1), F(1, 0), F(1, 1));
  PrincipalStretch<2> out;
  // Part 2: the two logarithms.
  out.eps[1] = 0.5 * std::log1p(q.m + q.r);
  out.eps[0] = std::log1p(q.j_minus_1) - out.eps[1];
  double ux, uy;
  const bool spread = hencky_2d_frame(q, ux, uy);
  out.U(0, 0) = uy;
  out.U(1, 0) = spread ? -ux : 0.0;
  out.U(0, 1) = ux;
  out.U(1, 1) = uy;
  return out;
}

}  // namespace detail

// Principal frame and Hencky strains of F, ε in ascending order (U's columns match). Solving
// for b − I keeps relative precision at the small strains of ice (|ε| ~ 1e-3), and log1p keeps
// it in the logarithm. 2D: the closed form above, inlined (tests/engine/test_principal_hencky.cpp
// checks it against Eigen and a long-double reference); 3D: Eigen's direct solver.
template <int Dim>
inline PrincipalStretch<Dim> principal_hencky(const Mat<Dim>& F) {
  if constexpr (Dim == 2) {
    return detail::principal_hencky_2d(F);
  } else {
    const Mat<Dim> b_minus_i = F * F.transpose() - Mat<Dim>::Identity();
    Eigen::SelfAdjointEigenSolver<Mat<Dim>> eig;
    eig.computeDirect(b_minus_i);
    PrincipalStretch<Dim> out;
    out.U = eig.eigenvectors();
    for (int a = 0; a < Dim; ++a) out.eps[a] = 0.5 * std::log1p(eig.eigenvalues()[a]);
    return out;
  }
}

template <int Dim>
inline Vec<Dim> principal_kirchhoff(const ElasticModuli& m, const Vec<Dim>& eps) {
  return (2.0 * m.mu * eps.array() + m.lambda * eps.sum()).matrix();
}

// 2D τ from the principal strains (e0 ≤ e1) and U's second column (ux, uy), in scalars (the
// engine's 2D block update calls it on a block of particles): τ₀ I + (τ₁ − τ₀) u uᵀ, below.
inline void kirchhoff_stress_2d(const ElasticModuli& m, double e0, double e1, double ux, double uy,
                                double& t00, double& t11, double& t01) {
  const double two_mu = 2.0 * m.mu, lam_tr = m.lambda * (e0 + e1);
  const double t0 = two_mu * e0 + lam_tr, t1 = two_mu * e1 + lam_tr;
  const double dt = t1 - t0;
  t00 = t0 + dt * ux * ux;
  t11 = t0 + dt * uy * uy;
  t01 = dt * ux * uy;
}

// τ = U diag(τ_i) Uᵀ. In 2D, with u = U's second column, U diag(τ₀, τ₁) Uᵀ = τ₀ I + (τ₁ − τ₀) u uᵀ
// (U orthonormal), which is exactly symmetric and needs 4 products instead of a 2×2×2 chain.
template <int Dim>
inline Mat<Dim> kirchhoff_stress(const ElasticModuli& m, const PrincipalStretch<Dim>& s) {
  if constexpr (Dim == 2) {
    Mat<2> tau;
    kirchhoff_stress_2d(m, s.eps[0], s.eps[1], s.U(0, 1), s.U(1, 1), tau(0, 0), tau(1, 1), tau(0, 1));
    tau(1, 0) = tau(0, 1);
    return tau;
  } else {
    return s.U * principal_kirchhoff<Dim>(m, s.eps).asDiagonal() * s.U.transpose();
  }
}

// Principal Hencky strains that produce a given principal Kirchhoff stress (the inverse law),
// used to load a geostatic initial stress into F_E.
template <int Dim>
inline Vec<Dim> hencky_strain_from_kirchhoff(const ElasticModuli& m, const Vec<Dim>& tau) {
  // tr τ = (2μ + dλ) tr ε, then ε_i = (τ_i − λ tr ε) / 2μ.
  const double tr_eps = tau.sum() / (2.0 * m.mu + Dim * m.lambda);
  return ((tau.array() - m.lambda * tr_eps) / (2.0 * m.mu)).matrix();
}

// Invariants (docs/model.md): p = −tr(τ)/d (compression positive), q = sqrt(3/2 dev τ : dev τ).
template <int Dim>
inline double pressure_of(const Mat<Dim>& tau) {
  return -tau.trace() / Dim;
}
template <int Dim>
inline double von_mises_of(const Mat<Dim>& tau) {
  const Mat<Dim> dev = tau - (tau.trace() / Dim) * Mat<Dim>::Identity();
  return std::sqrt(1.5 * dev.squaredNorm());
}

}  // namespace crevasse
