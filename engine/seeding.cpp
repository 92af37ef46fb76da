#include "engine/seeding.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

namespace crevasse {

template <int Dim>
Particles<Dim> seed_ice(const SceneConfig& scene, const ElasticModuli& moduli, const Bed* bed) {
  Particles<Dim> particles;
  const double dx = scene.dx;
  const int ppc = scene.particles_per_cell_axis;
  const double h = dx / ppc;  // particle spacing
  const double rho = scene.density;
  Vec<Dim> lo, hi;
  double surface_z;
  // Draped ice: the slab continues past the top of the step between the bed and z_b + H_i.
  const bool draped = scene.body == Body::slab && scene.draped_length > 0.0 && bed != nullptr;
  if (scene.body == Body::slab) {
    lo.setZero();
    hi.setZero();
    lo[0] = 0.0;
    hi[0] = scene.upstream_length + (draped ? scene.draped_length : 0.0);
    lo[up_axis<Dim>] = draped ? 0.0 : scene.step_height;
    hi[up_axis<Dim>] = scene.step_height + scene.ice_thickness;
    if constexpr (Dim == 3) {
      lo[1] = 0.0;
      hi[1] = scene.width;
    }
  } else {
    lo = to_vec<Dim>(scene.box_min);
    hi = to_vec<Dim>(scene.box_max);
  }
  surface_z = hi[up_axis<Dim>];

  IVec<Dim> count;
  for (int a = 0; a < Dim; ++a) count[a] = std::max(1, static_cast<int>(std::round((hi[a] - lo[a]) / h)));
  std::mt19937_64 rng(scene.seed);
  std::uniform_real_distribution<double> jitter(-scene.jitter * h, scene.jitter * h);

  // Geostatic initial stress (docs/model.md): σ_zz = −ρ g (s − z), lateral stresses
  // K0·σ_zz with K0 = ν/(1 − ν), the uniaxial-strain state of a laterally confined slab. It is
  // loaded into F_E through the inverse Hencky law with τ = J σ (two fixed-point passes: J − 1
  // is of order 1e-3, so the second pass already changes τ by ~1e-6 relative).
  // "hydrostatic" (K0 = 1) is the cryostatic state of ice that has flowed long enough for its
  // deviatoric stress to relax: no shear stress at rest, so a low q_y does not yield at t = 0.
  const bool prestressed = scene.initial_stress != InitialStress::none && scene.has(Effect::gravity);
  const double g_vertical = scene.gravity * std::cos(scene.gravity_tilt_deg * std::numbers::pi / 180.0);
  const double k0 = scene.initial_stress == InitialStress::hydrostatic ? 1.0 : scene.poisson_ratio / (1.0 - scene.poisson_ratio);
  const double cell_volume = std::pow(h, Dim);

  std::size_t total = 1;
  for (int a = 0; a < Dim; ++a) total *= static_cast<std::size_t>(count[a]);
  particles.x.reserve(draped ? total / 2 : total);
  IVec<Dim> idx = IVec<Dim>::Zero();
  for (std::size_t n = 0; n < total; ++n) {
    std::size_t r = n;
    for (int a = Dim - 1; a >= 0; --a) {
      idx[a] = static_cast<int>(r % count[a]);
      r /= count[a];
    }
    Vec<Dim> pos;
    for (int a = 0; a < Dim; ++a) pos[a] = lo[a] + (idx[a] + 0.5) * h + jitter(rng);
    if (draped) {
      // Keep the lattice points between the bed and the surface, judged at the unjittered
      // lattice position so jitter does not change the particle count.
      const double xl = lo[0] + (idx[0] + 0.5) * h, zl = lo[up_axis<Dim>] + (idx[up_axis<Dim>] + 0.5) * h;
      const double zb = bed->height_at(xl);
      if (zl < zb || zl > zb + scene.ice_thickness) continue;
      surface_z = zb + scene.ice_thickness;
    }
    Mat<Dim> fe = Mat<Dim>::Identity();
    Mat<Dim> tau = Mat<Dim>::Zero();
    double vol0 = cell_volume;
    if (prestressed) {
      Vec<Dim> sigma = Vec<Dim>::Constant(-k0 * rho * g_vertical * (surface_z - pos[up_axis<Dim>]));
      sigma[up_axis<Dim>] = -rho * g_vertical * (surface_z - pos[up_axis<Dim>]);
      Vec<Dim> tau_p = sigma;
      Vec<Dim> eps = Vec<Dim>::Zero();
      for (int pass = 0; pass < 2; ++pass) {
        eps = hencky_strain_from_kirchhoff<Dim>(moduli, tau_p);
        tau_p = sigma * std::exp(eps.sum());
      }
      fe = eps.array().exp().matrix().asDiagonal();
      tau = principal_kirchhoff<Dim>(moduli, eps).asDiagonal();
      vol0 = cell_volume / std::exp(eps.sum());  // the lattice volume is the compressed one
    }
    particles.push_back(pos, rho * cell_volume, vol0, fe, tau);
  }
  particles.shrink_to_fit();
  if (scene.has(Effect::plasticity)) particles.eps_v_p.assign(particles.size(), 0.0);
  if (scene.has(Effect::drive) && scene.drive_boundary == DriveBoundary::piston) {
    particles.drive_x0.assign(particles.size(), std::numeric_limits<double>::quiet_NaN());
    for (std::size_t p = 0; p < particles.size(); ++p)
      if (particles.x[p][0] < lo[0] + dx) particles.drive_x0[p] = particles.x[p][0];
  }
  return particles;
}

template Particles<2> seed_ice<2>(const SceneConfig&, const ElasticModuli&, const Bed*);
template Particles<3> seed_ice<3>(const SceneConfig&, const ElasticModuli&, const Bed*);

}  // namespace crevasse
