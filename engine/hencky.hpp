#pragma once
// Hencky (logarithmic-strain) elasticity. With the left stretch of F_E written b = F_E F_Eᵀ =
// U diag(Σ²) Uᵀ, the principal Hencky strains are ε = log Σ and the Kirchhoff stress is
// τ = U (2μ ε + λ tr(ε) I) Uᵀ (SPEC §3). Only the symmetric eigenproblem of b is needed,
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
  // Bulk modulus in the SPEC's d-dimensional convention: p = −tr(τ)/d = −K_d tr(ε).
  double bulk(int dim) const { return lambda + 2.0 * mu / dim; }
  // P-wave modulus λ + 2μ, which sets the explicit time step.
  double p_wave_modulus() const { return lambda + 2.0 * mu; }
};

template <int Dim>
struct PrincipalStretch {
  Mat<Dim> U;          // eigenvectors of b (columns)
  Vec<Dim> eps;        // principal Hencky strains ε_i = ½ log(eigenvalue_i of b)
};

// Principal frame and Hencky strains of F. Solving for b − I keeps relative precision at the
// small strains of ice (|ε| ~ 1e-3), and log1p keeps it in the logarithm.
template <int Dim>
inline PrincipalStretch<Dim> principal_hencky(const Mat<Dim>& F) {
  const Mat<Dim> b_minus_i = F * F.transpose() - Mat<Dim>::Identity();
  Eigen::SelfAdjointEigenSolver<Mat<Dim>> eig;
  eig.computeDirect(b_minus_i);
  PrincipalStretch<Dim> out;
  out.U = eig.eigenvectors();
  for (int a = 0; a < Dim; ++a) out.eps[a] = 0.5 * std::log1p(eig.eigenvalues()[a]);
  return out;
}

template <int Dim>
inline Vec<Dim> principal_kirchhoff(const ElasticModuli& m, const Vec<Dim>& eps) {
  return (2.0 * m.mu * eps.array() + m.lambda * eps.sum()).matrix();
}

template <int Dim>
inline Mat<Dim> kirchhoff_stress(const ElasticModuli& m, const PrincipalStretch<Dim>& s) {
  return s.U * principal_kirchhoff<Dim>(m, s.eps).asDiagonal() * s.U.transpose();
}

// Principal Hencky strains that produce a given principal Kirchhoff stress (the inverse law),
// used to load a geostatic initial stress into F_E.
template <int Dim>
inline Vec<Dim> hencky_strain_from_kirchhoff(const ElasticModuli& m, const Vec<Dim>& tau) {
  // tr τ = (2μ + dλ) tr ε, then ε_i = (τ_i − λ tr ε) / 2μ.
  const double tr_eps = tau.sum() / (2.0 * m.mu + Dim * m.lambda);
  return ((tau.array() - m.lambda * tr_eps) / (2.0 * m.mu)).matrix();
}

// SPEC invariants: p = −tr(τ)/d (compression positive), q = sqrt(3/2 dev τ : dev τ).
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
