#pragma once
// The particle update, the second half of G2P: move the particle by Δt v, F_E ← ΔF·F_E with
// ΔF = I + Δt C (rescaled to the averaged volume change when the scene averages it), then the
// constitutive update: the capped von Mises return mapping when the scene is plastic, and the
// Kirchhoff stress of the new F_E.
// Reads the particle's v, C, F_E and ε_v^p; writes x, F_E, τ and ε_v^p.
// One implementation for any dimension, one particle at a time (update_particle), and one for
// 2D over blocks of particles that the compiler vectorises (update_particles_2d), equal to the
// first to the bit (tests BlockUpdate.*; bench/state_hash).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "engine/capped_von_mises.hpp"
#include "engine/fast_math.hpp"
#include "engine/hencky.hpp"
#include "engine/particles.hpp"

namespace crevasse {

// pow(s, 1/d), the root of a volume ratio; in 2D by pow_half, the same double at less cost.
template <int Dim>
inline double volume_root(double s) {
  if constexpr (Dim == 2) return pow_half(s);
  else return std::pow(s, 1.0 / Dim);
}

// ΔJ_used/ΔJ_p from the stencil's Σ w ΔJ̄ (jbar) and Σ w (wsum) and the particle's own ΔJ_p (dj),
// with `intact` = 1 − D the particle's share of the average. Selects, no branch (a lane's unused
// quotient may be inf or NaN; it is never selected).
inline double volume_scale_of(double jbar, double wsum, double dj, double intact) {
  const double averaged = intact * (jbar / wsum) + (1.0 - intact) * dj;
  const double used = wsum > 0.0 ? averaged : dj;
  const double ratio = used / dj;
  return (dj > 0.0 && used > 0.0) ? ratio : 1.0;
}

// The constitutive update from the trial F_E and its principal Hencky strains: the return
// mapping when Plastic (softening = e^{−ζ ε_v^p} at the start of the step), then F_E and τ.
template <int Dim, bool Plastic>
[[gnu::always_inline]] inline void constitutive_update(const ElasticModuli& moduli, const CappedVonMisesParams& plastic,
                                                       Mat<Dim> fe, PrincipalStretch<Dim> s, double softening,
                                                       Particles<Dim>& P, std::size_t p) {
  if constexpr (Plastic) {
    const ReturnResult<Dim> ret = return_map_capped_von_mises<Dim>(s.eps, P.eps_v_p[p], moduli, plastic, softening);
    if (ret.cap_active || ret.shear_active) {
      // F_E = U exp(ε') Uᵀ R: rescale the left stretch in its principal frame.
      const Vec<Dim> scale = (ret.eps - s.eps).array().exp();
      fe = s.U * scale.asDiagonal() * s.U.transpose() * fe;
      s.eps = ret.eps;
      P.eps_v_p[p] += ret.delta_eps_v;
    }
  }
  P.F_e[p] = fe;
  P.tau[p] = kirchhoff_stress<Dim>(moduli, s);
}

// One particle, any dimension.
template <int Dim, bool Plastic>
[[gnu::always_inline]] inline void update_particle(Particles<Dim>& P, std::size_t p, double dt, double volume_scale,
                                                   double softening, const ElasticModuli& moduli,
                                                   const CappedVonMisesParams& plastic) {
  P.x[p] += dt * P.v[p];
  Mat<Dim> df = Mat<Dim>::Identity() + dt * P.C[p];
  if (volume_scale != 1.0) df *= volume_root<Dim>(volume_scale);
  const Mat<Dim> fe = df * P.F_e[p];
  constitutive_update<Dim, Plastic>(moduli, plastic, fe, principal_hencky<Dim>(fe), softening, P, p);
}

// What the 2D block update needs of a particle before its update: inputs(p, jbar, wsum, dj, soft)
// fills the volume-average sums (read only when Average) and e^{−ζ ε_v^p};
// `damage` says whether the particle's share of the average is 1 − D. finish(p) is called on each
// particle once it is written.
//
// Per block of kBlock particles: (1) one by one, the inputs; (2) over the block, the volume ratio
// and its square root with pow_half's test; (3) pow where that test failed; (4) over the block,
// ΔF·F_E and the closed-form eigen-solve up to the logarithms' arguments; (5) the two logarithms,
// one by one; (6) over the block, the frame, τ and the two yield tests; then the stores. The
// compiler keeps two particles per vector register in (2), (4) and (6). A particle whose trial
// state is outside a yield surface (at cracks: many once a glacier has cracked) goes from the
// block's trial state through the return mapping (constitutive_update), as in update_particle.
template <bool Plastic, bool Average, class Inputs, class Finish>
inline void update_particles_2d(Particles<2>& P, std::size_t begin, std::size_t end, double dt, bool damage,
                                const ElasticModuli& moduli, const CappedVonMisesParams& plastic_params,
                                Inputs&& inputs, Finish&& finish) {
  constexpr std::size_t kBlock = 32;
  double jbar[kBlock], wsum[kBlock], dj[kBlock], vs[kBlock], scale[kBlock], soft[kBlock];
  std::int64_t need_pow[kBlock];
  double f00[kBlock], f01[kBlock], f10[kBlock], f11[kBlock];
  double m[kBlock], h[kBlock], d[kBlock], r[kBlock], jm1[kBlock], e0[kBlock], e1[kBlock];
  double t00[kBlock], t11[kBlock], t01[kBlock], ux[kBlock], uy[kBlock];
  std::int64_t spread[kBlock];
  std::int64_t elastic[kBlock];  // 0 or 1: the width of a double, so that the loop below vectorises
  for (std::size_t b = begin; b < end; b += kBlock) {
    const std::size_t n = std::min(kBlock, end - b);
    for (std::size_t i = 0; i < n; ++i) inputs(b + i, jbar[i], wsum[i], dj[i], soft[i]);
    // The volume ratio and its root (pow_half split in two: the square root and its test over
    // the block, pow one by one where the test fails). ΔF·s with s = 1 is exact, so the
    // unscaled particles need no branch below.
    if constexpr (Average) {
      for (std::size_t i = 0; i < n; ++i) {
        vs[i] = volume_scale_of(jbar[i], wsum[i], dj[i], damage ? soft[i] : 1.0);
        const double root = std::sqrt(vs[i]);
        const bool unscaled = vs[i] == 1.0;
        scale[i] = unscaled ? 1.0 : root;
        need_pow[i] = !unscaled & !sqrt_is_pow_half(vs[i], root);
      }
      for (std::size_t i = 0; i < n; ++i)
        if (need_pow[i]) scale[i] = std::pow(vs[i], 0.5);
    } else {
      for (std::size_t i = 0; i < n; ++i) scale[i] = 1.0;
    }
    for (std::size_t i = 0; i < n; ++i) {
      const double* c = P.C[b + i].data();  // column-major: C00, C10, C01, C11
      const double* fe = P.F_e[b + i].data();
      const double s = scale[i];
      const double d00 = (1.0 + dt * c[0]) * s, d10 = (0.0 + dt * c[1]) * s;
      const double d01 = (0.0 + dt * c[2]) * s, d11 = (1.0 + dt * c[3]) * s;
      f00[i] = d00 * fe[0] + d01 * fe[1];
      f10[i] = d10 * fe[0] + d11 * fe[1];
      f01[i] = d00 * fe[2] + d01 * fe[3];
      f11[i] = d10 * fe[2] + d11 * fe[3];
      const detail::Hencky2dParts q = detail::hencky_2d_parts(f00[i], f01[i], f10[i], f11[i]);
      m[i] = q.m;
      h[i] = q.h;
      d[i] = q.d;
      r[i] = q.r;
      jm1[i] = q.j_minus_1;
    }
    for (std::size_t i = 0; i < n; ++i) {
      e1[i] = 0.5 * std::log1p(m[i] + r[i]);
      e0[i] = std::log1p(jm1[i]) - e1[i];
    }
    for (std::size_t i = 0; i < n; ++i) {
      spread[i] = detail::hencky_2d_frame({m[i], h[i], d[i], r[i], jm1[i]}, ux[i], uy[i]);
      kirchhoff_stress_2d(moduli, e0[i], e1[i], ux[i], uy[i], t00[i], t11[i], t01[i]);
      if constexpr (Plastic) elastic[i] = admissible_2d(e0[i], e1[i], moduli, plastic_params, soft[i]);
    }
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t p = b + i;
      P.x[p] += dt * P.v[p];
      if constexpr (Plastic) {
        if (!elastic[i]) {
          // Outside a yield surface: the return mapping, from the block's trial state, which
          // is update_particle's to the bit (principal_hencky_2d chains the same parts).
          Mat<2> trial;
          trial << f00[i], f01[i], f10[i], f11[i];
          PrincipalStretch<2> st;
          st.eps << e0[i], e1[i];
          st.U << uy[i], ux[i], spread[i] ? -ux[i] : 0.0, uy[i];
          constitutive_update<2, true>(moduli, plastic_params, trial, st, soft[i], P, p);
          finish(p);
          continue;
        }
      }
      Mat<2>& fe = P.F_e[p];
      fe(0, 0) = f00[i];
      fe(1, 0) = f10[i];
      fe(0, 1) = f01[i];
      fe(1, 1) = f11[i];
      Mat<2>& tau = P.tau[p];
      tau(0, 0) = t00[i];
      tau(1, 1) = t11[i];
      tau(0, 1) = t01[i];
      tau(1, 0) = t01[i];
      finish(p);
    }
  }
}

}  // namespace crevasse
