// Glen creep of the deviator (engine/capped_von_mises.hpp, docs/model.md "Creep"), checked
// against closed forms: the steady stress of a constant shear rate, Maxwell relaxation (n = 1),
// the rate law in Glen's own terms (ε̇_e = A τ_e^n), and the time scaling of the drive.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/capped_von_mises.hpp"
#include "engine/hencky.hpp"
#include "engine/scene.hpp"

namespace crevasse {
namespace {

const ElasticModuli kModuli = ElasticModuli::from_young_poisson(1.0e9, 0.3);

CappedVonMisesParams creeping(double rate, double n, double dt) {
  CappedVonMisesParams p;
  p.tensile_strength_c = 1.0e6;
  p.shear_strength_qy = 1.0e7;
  p.creep_exponent = n;
  p.creep_increment = dt * rate;
  return p;
}

double von_mises_q(const Vec<2>& eps) {
  const double tr = eps.sum();
  const Vec<2> dev = eps.array() - tr / 2;
  return von_mises_of_strain_deviator(kModuli, dev.norm());
}

// Pure shear at a constant rate: the deviatoric Hencky strain (e, −e) grows by ė Δt each step,
// an equivalent strain rate ε̄̇ = (2/√3) ė. At steady state all of it is creep, so the
// backward-Euler step gives exactly rate·q^n = ε̄̇: q = (ε̄̇/rate)^{1/n}. Tolerance 1e-9 relative:
// the approach is geometric and 4000 steps of 40 Maxwell times leave nothing of the start.
TEST(Creep, ConstantShearRateReachesGlensSteadyStress) {
  for (const double n : {1.0, 3.0, 4.0}) {
    SCOPED_TRACE(n);
    const double rate_dot = 0.02;                    // ė [1/s], of the order of V_x/H_i
    const double eq_rate = 2.0 / std::sqrt(3.0) * rate_dot;
    const double q_target = 3.0e5;                  // choose the steady stress, derive the rate
    const double rate = eq_rate / std::pow(q_target, n);
    const double maxwell = q_target / (3.0 * kModuli.mu * eq_rate);  // q/(3μ ε̄̇): load time
    const double dt = maxwell / 100.0;
    const CappedVonMisesParams p = creeping(rate, n, dt);
    Vec<2> eps = Vec<2>::Zero();
    for (int step = 0; step < 4000; ++step) {
      Vec<2> trial = eps;
      trial(0) += rate_dot * dt;
      trial(1) -= rate_dot * dt;
      eps = return_map_capped_von_mises<2>(trial, 0.0, kModuli, p).eps;
    }
    EXPECT_NEAR(von_mises_q(eps), q_target, 1e-9 * q_target);
    EXPECT_NEAR(eps.sum(), 0.0, 1e-18);  // creep is isochoric
  }
}

// n = 1 is a Maxwell body: with no further strain, q decays as e^{−3μ·rate·t}. Backward Euler
// gives q_k = q_0 (1 + 3μ·rate·Δt)^{−k} exactly; compare with that to round-off, and with the
// exponential within the scheme's first-order error (k(h − ln(1 + h)) ≈ k h²/2 = 1.5 % for
// h = Δt/τ = 0.01 over k = 300 steps; 2 % allowed).
TEST(Creep, LinearCreepRelaxesLikeAMaxwellBody) {
  const double tau = 0.05;  // relaxation time [s]
  const double rate = 1.0 / (3.0 * kModuli.mu * tau);
  const double dt = tau / 100.0;
  const CappedVonMisesParams p = creeping(rate, 1.0, dt);
  Vec<2> eps(2.0e-4, -2.0e-4);
  const double q0 = von_mises_q(eps);
  for (int step = 0; step < 300; ++step) eps = return_map_capped_von_mises<2>(eps, 0.0, kModuli, p).eps;
  const double q = von_mises_q(eps);
  EXPECT_NEAR(q, q0 * std::pow(1.0 + dt / tau, -300), 1e-10 * q0);
  EXPECT_NEAR(q / q0, std::exp(-3.0), 0.02 * std::exp(-3.0));
}

// Below q_y the creep step and the ceiling q_y combine as min: a trial far past q_y with a slow
// creep ends on q_y, as without creep.
TEST(Creep, ShearStrengthStaysTheCeiling) {
  CappedVonMisesParams p = creeping(1e-30, 3.0, 1e-3);
  p.shear_strength_qy = 1.0e5;
  const Vec<2> trial(1.0e-3, -1.0e-3);  // q ≈ 1.3 MPa
  const double q = von_mises_q(return_map_capped_von_mises<2>(trial, 0.0, kModuli, p).eps);
  EXPECT_NEAR(q, 1.0e5, 1e-6);
}

// The scene's rate is Glen's law, ε̇_e = A τ_e^n with τ_e = q/√3 and ε̇_e = (√3/2) ε̄̇, sped up by
// drive.speed / field_speed; without a drive it runs in real time.
TEST(Creep, SceneRateIsGlensLawSpedUpLikeTheDrive) {
  SceneConfig s;
  s.effects = {Effect::gravity, Effect::drive, Effect::plasticity};
  s.creep_rate_factor = 2.4e-24;
  s.creep_exponent = 3.0;
  s.creep_field_speed = 3.17e-6;
  s.drive_speed = 4.0;
  const double tau_e = 1.0e5;
  const double q = std::sqrt(3.0) * tau_e;
  const double glen_real = 2.4e-24 * std::pow(tau_e, 3.0);  // ε̇_e of the real glacier
  const double speed_up = 4.0 / 3.17e-6;
  EXPECT_NEAR(std::sqrt(3.0) / 2.0 * s.creep_rate() * std::pow(q, 3.0), speed_up * glen_real,
              1e-12 * speed_up * glen_real);
  s.effects = {Effect::gravity, Effect::plasticity};
  EXPECT_NEAR(std::sqrt(3.0) / 2.0 * s.creep_rate() * std::pow(q, 3.0), glen_real, 1e-12 * glen_real);
  s.creep_rate_factor = 0.0;
  EXPECT_EQ(s.creep_rate(), 0.0);
}

}  // namespace
}  // namespace crevasse
