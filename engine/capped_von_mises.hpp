#pragma once
// Capped von Mises plasticity with a softening tensile cap (docs/model.md), returned in principal
// Hencky strain space. With Hencky elasticity the volumetric and deviatoric parts decouple, so
// the closest-point return onto {p ≥ p_c(ε_v^p), q ≤ q_y} is two independent clamps that
// commute (docs/model.md):
//  * cap:   shift tr ε by −Δ (Δ/d on each principal strain), ε_v^p += Δ, p → p_c(ε_v^p + Δ);
//  * shear: scale dev ε radially so that q = q_y (isochoric: tr ε unchanged); with creep, so
//    that q is the creep step's q when that is lower.
#include <algorithm>
#include <cmath>

#include "engine/hencky.hpp"

namespace crevasse {

struct CappedVonMisesParams {
  double tensile_strength_c = 0.0;  // c [Pa], p_c(0) = −c
  double shear_strength_qy = 0.0;   // q_y [Pa]
  double softening_zeta = 0.0;      // ζ [-]; 0 = perfectly plastic cap
  // Damage also softens the shear strength, q_y·exp(−ζ ε_v^p): without it a fully opened
  // particle keeps q_y and, under overburden, still carries horizontal tension of the order of
  // ρ g d (the cap bounds only the mean stress), so a cracked block hangs on as a hinge instead
  // of separating. The closest public code of this family (matter's capped von Mises, Blatny &
  // Gaume 2025, GMD 18, 9149) softens q_y with the same rate. docs/model.md discusses it.
  bool damage_softens_shear = true;
  // Residual strength of damaged ice as rubble: q_y never drops below M·max(p, 0) (a
  // Drucker–Prager-like friction line; M = 6 sin φ/(3 − sin φ) = 1.2 for φ = 30°). 0 = none.
  double residual_friction_m = 0.0;
  // Creep (docs/model.md, "Creep"): the deviator also relaxes by Glen's law, the equivalent
  // plastic strain rate being creep_rate·q^n in simulated time. creep_increment = Δt·creep_rate
  // is set by the engine each step; 0 = no creep (the rate-independent law).
  double creep_increment = 0.0;
  double creep_exponent = 3.0;
  // Softening with a length (docs/model.md, "Softening with a length"). explicit_softening: the
  // softening factor passed to the return mapping (from the nonlocal ε̂, nonlocal_opening.hpp)
  // holds over the step, so the cap returns as perfectly plastic at c·e^{−ζ ε̂}.
  // cap_relaxed_fraction: a Duvaut–Lions viscous cap (Needleman 1988, CMAME 67:69), the step
  // takes the fraction (Δt/τ)/(1 + Δt/τ) of the inviscid return; set by the engine each step,
  // 1 = rate-independent.
  bool explicit_softening = false;
  double cap_relaxed_fraction = 1.0;
  // Brittle cap (the variant of the capped von Mises law in Blatny & Gaume's matter code): a
  // state past the cap loses its whole elastic strain, F_E → the rotation, its trace going into
  // ε_v^p; the opened ice carries no stress in that step, shear included.
  bool brittle_cap = false;
};

// q at the end of one backward-Euler creep step from the trial q_t: the root of
// f(q) = q + 3μ a q^n − q_t with a = Δt·creep_rate (a radial return moves q by 3μ per unit of
// equivalent plastic strain). f is increasing and convex on q ≥ 0 and both starting values
// below have f ≥ 0, so Newton falls monotonically onto the root without overshooting it.
inline double creep_relaxed(double q_t, double three_mu_a, double n) {
  if (!(q_t > 0.0)) return q_t;
  const auto pow_n1 = [n](double q) { return n == 3.0 ? q * q : std::pow(q, n - 1.0); };
  double q = std::min(q_t, std::pow(q_t / three_mu_a, 1.0 / n));
  for (int it = 0; it < 100; ++it) {
    const double qn1 = pow_n1(q);
    const double step = (q + three_mu_a * qn1 * q - q_t) / (1.0 + n * three_mu_a * qn1);
    q -= step;
    if (std::abs(step) <= 1e-14 * q_t) break;
  }
  return q;
}

// The softening factor e^{−ζ ε_v^p} of the cap and of the shear strength. e^{−ζ·0} is exactly 1,
// so intact ice (most of a glacier) skips the exponential.
inline double softening_factor(const CappedVonMisesParams& p, double eps_v_p) {
  return eps_v_p == 0.0 ? 1.0 : std::exp(-p.softening_zeta * eps_v_p);
}

// Shear strength with the softening factor f = e^{−ζ ε_v^p} of the opening already evaluated.
// A select, not a branch, so that the engine's 2D block update vectorises.
inline double shear_strength_softened(const CappedVonMisesParams& p, double f, double pressure) {
  const double intact = p.shear_strength_qy * f;
  const double softened =
      std::min(p.shear_strength_qy, std::max(intact, p.residual_friction_m * std::max(pressure, 0.0)));
  return p.damage_softens_shear ? softened : p.shear_strength_qy;
}

// Shear strength at a given opening: q_y, or q_y·exp(−ζ ε_v^p) when damage softens shear.
inline double shear_strength(const CappedVonMisesParams& p, double eps_v_p, double pressure) {
  if (!p.damage_softens_shear) return p.shear_strength_qy;
  return shear_strength_softened(p, softening_factor(p, eps_v_p), pressure);
}

// The two yield tests of a trial state, shared by the return mapping below and the engine's 2D
// block update (admissible_2d), so both decide with the same operations.
inline bool cap_violated(double p_trial, const CappedVonMisesParams& p, double softening) {
  return p_trial < -p.tensile_strength_c * softening;
}
// q = sqrt(3/2)·2μ‖dev ε‖ from ‖dev ε‖.
inline double von_mises_of_strain_deviator(const ElasticModuli& m, double dev_norm) {
  return std::sqrt(6.0) * m.mu * dev_norm;
}

template <int Dim>
struct ReturnResult {
  Vec<Dim> eps;            // returned principal Hencky strains
  double delta_eps_v = 0;  // increment of ε_v^p (≥ 0)
  bool cap_active = false;
  bool shear_active = false;
};

// Tensile cap pressure p_c(ε_v^p) = −c·exp(−ζ ε_v^p).
inline double cap_pressure(const CappedVonMisesParams& p, double eps_v_p) {
  return -p.tensile_strength_c * softening_factor(p, eps_v_p);
}

// Solves g(Δ) = p_tr + K Δ + c·exp(−ζ(ε_v + Δ)) = 0 for Δ > 0, given g(0) < 0 (the trial state
// is past the cap). g is convex (g'' = cζ² e^{−ζ(ε+Δ)} > 0) and g(0) < 0, so {g ≤ 0} is an
// interval starting at 0 and the root is unique for every ζ, including cζ ≥ K where the local
// law snaps back (g is then first decreasing). The bracket [0, −p_tr/K] holds it (g(hi) =
// c·e^{..} > 0); Newton steps are taken when they stay inside the bracket, bisection otherwise.
// The returned state lies exactly on the softened cap p = p_c(ε_v + Δ), so the yield condition
// holds at the end of every step (before engine 0.3.1 the case cζ ≥ K was returned explicitly to
// the start-of-step cap and ended outside the softened one).
inline double cap_return_increment(double p_trial, double bulk_k, double eps_v_p,
                                   const CappedVonMisesParams& p) {
  const double c = p.tensile_strength_c;
  const double zeta = p.softening_zeta;
  if (zeta <= 0.0) return (cap_pressure(p, eps_v_p) - p_trial) / bulk_k;  // perfectly plastic cap: exact
  double lo = 0.0;
  double hi = -p_trial / bulk_k;  // g(hi) = c·exp(..) > 0 because p_trial < 0
  double d = hi;
  for (int it = 0; it < 200; ++it) {
    const double e = c * std::exp(-zeta * (eps_v_p + d));
    const double g = p_trial + bulk_k * d + e;
    if (g > 0.0) hi = d; else lo = d;
    const double dg = bulk_k - zeta * e;
    double next = d - g / dg;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - d) <= 1e-15 * std::max(1.0, std::abs(d)) + 1e-300) return next;
    d = next;
  }
  return d;
}

// `softening` is e^{−ζ ε_v^p} at the start of the step (softening_factor): the engine has it
// from the volume averaging and passes it in, so the exponential is evaluated once per particle.
template <int Dim>
inline ReturnResult<Dim> return_map_capped_von_mises(const Vec<Dim>& eps_trial, double eps_v_p,
                                                    const ElasticModuli& m,
                                                    const CappedVonMisesParams& p,
                                                    double softening) {
  ReturnResult<Dim> r;
  r.eps = eps_trial;
  const double k = m.bulk(Dim);
  const double tr = eps_trial.sum();
  const double p_trial = -k * tr;
  if (p.brittle_cap && cap_violated(p_trial, p, softening)) {
    r.eps.setZero();
    r.delta_eps_v = tr;
    r.cap_active = true;
    return r;
  }
  if (cap_violated(p_trial, p, softening)) {
    const double inviscid = p.explicit_softening ? (-p.tensile_strength_c * softening - p_trial) / k
                                                 : cap_return_increment(p_trial, k, eps_v_p, p);
    const double delta = p.cap_relaxed_fraction * inviscid;
    r.eps.array() -= delta / Dim;
    r.delta_eps_v = delta;
    r.cap_active = true;
  }
  const double tr_new = r.eps.sum();
  Vec<Dim> dev = r.eps.array() - tr_new / Dim;
  const double q_trial = von_mises_of_strain_deviator(m, dev.norm());
  const double q_y = r.cap_active && !p.explicit_softening ? shear_strength(p, eps_v_p + r.delta_eps_v, -k * tr_new)
                                  : shear_strength_softened(p, softening, -k * tr_new);
  const double q_end = p.creep_increment > 0.0
                           ? std::min(q_y, creep_relaxed(q_trial, 3.0 * m.mu * p.creep_increment, p.creep_exponent))
                           : q_y;
  if (q_trial > q_end) {
    dev *= q_end / q_trial;
    r.eps = (dev.array() + tr_new / Dim).matrix();
    r.shear_active = true;
  }
  return r;
}

// Whether the 2D trial state (principal strains e0, e1) lies inside both surfaces, by the tests
// of return_map_capped_von_mises<2> (cap_violated, von_mises_of_strain_deviator,
// shear_strength_softened, on the same trace and deviator): the engine's 2D block update keeps
// such a particle's trial state and sends the others through the return mapping above. Written
// without branches, so that it vectorises over a block.
inline bool admissible_2d(double e0, double e1, const ElasticModuli& m, const CappedVonMisesParams& p,
                          double softening) {
  const double k = m.bulk(2);
  const double tr = e0 + e1;
  const double half = tr / 2;
  const double d0 = e0 - half, d1 = e1 - half;
  const double q_trial = von_mises_of_strain_deviator(m, std::sqrt(d0 * d0 + d1 * d1));
  const double q_y = shear_strength_softened(p, softening, -k * tr);
  // Creeping ice relaxes at every step: none of it keeps its trial state.
  return !cap_violated(-k * tr, p, softening) & !(q_trial > q_y) & !(p.creep_increment > 0.0);
}

template <int Dim>
inline ReturnResult<Dim> return_map_capped_von_mises(const Vec<Dim>& eps_trial, double eps_v_p,
                                                    const ElasticModuli& m,
                                                    const CappedVonMisesParams& p) {
  return return_map_capped_von_mises<Dim>(eps_trial, eps_v_p, m, p, softening_factor(p, eps_v_p));
}

}  // namespace crevasse
