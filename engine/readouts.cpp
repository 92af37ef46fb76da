#include "engine/readouts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/hencky.hpp"

namespace crevasse {

template <int Dim>
double total_mass(const Particles<Dim>& P) {
  double m = 0.0;
  for (double v : P.mass) m += v;
  return m;
}

template <int Dim>
Vec<Dim> total_momentum(const Particles<Dim>& P) {
  Vec<Dim> s = Vec<Dim>::Zero();
  for (std::size_t p = 0; p < P.size(); ++p) s += P.mass[p] * P.v[p];
  return s;
}

template <int Dim>
double kinetic_energy(const Particles<Dim>& P) {
  double e = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) e += 0.5 * P.mass[p] * P.v[p].squaredNorm();
  return e;
}

template <int Dim>
double gravitational_potential_energy(const Particles<Dim>& P, double gravity) {
  double e = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) e += P.mass[p] * gravity * P.x[p][up_axis<Dim>];
  return e;
}

template <int Dim>
double cap_dissipated_energy(const Particles<Dim>& P, const CappedVonMisesParams& plastic) {
  if (!P.has_plastic_state()) return 0.0;
  const double c = plastic.tensile_strength_c, z = plastic.softening_zeta;
  double e = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    const double eps = P.eps_v_p[p];
    e += P.vol0[p] * (z > 0 ? c / z * (-std::expm1(-z * eps)) : c * eps);
  }
  return e;
}

template <int Dim>
double max_yield_violation(const Particles<Dim>& P, const CappedVonMisesParams& plastic) {
  if (!P.has_plastic_state()) return 0.0;
  double worst = -std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < P.size(); ++p) {
    const double pr = pressure_of<Dim>(P.tau[p]);
    const double q = von_mises_of<Dim>(P.tau[p]);
    const double pc = cap_pressure(plastic, P.eps_v_p[p]);
    worst = std::max({worst, (pc - pr) / plastic.tensile_strength_c,
                      (q - shear_strength(plastic, P.eps_v_p[p], pr)) / plastic.tensile_strength_c});
  }
  return worst;
}

template <int Dim>
double ice_front_x(const Particles<Dim>& P, const SceneConfig& scene, double min_fraction) {
  if (P.size() == 0) return 0.0;
  const double dx = scene.dx;
  double xmin = P.x[0][0], xmax = xmin;
  for (std::size_t p = 0; p < P.size(); ++p) {
    xmin = std::min(xmin, P.x[p][0]);
    xmax = std::max(xmax, P.x[p][0]);
  }
  const auto columns = static_cast<std::size_t>((xmax - xmin) / dx) + 1;
  std::vector<double> volume(columns, 0.0);
  for (std::size_t p = 0; p < P.size(); ++p)
    volume[static_cast<std::size_t>((P.x[p][0] - xmin) / dx)] += P.mass[p] / scene.density;
  double across = 1.0;  // 3D: the width of the ice across the flow
  if constexpr (Dim == 3) across = scene.body == Body::slab ? scene.width : scene.box_max[1] - scene.box_min[1];
  const double thickness = scene.body == Body::slab ? scene.ice_thickness : scene.box_max[Dim - 1] - scene.box_min[Dim - 1];
  const double full = min_fraction * thickness * dx * across;
  // Gaps upstream of the step top (a crack near the piston) do not end the ice: the walk
  // only stops at a gap downstream of it.
  const double gaps_from_x = scene.body == Body::slab ? scene.step_top_x() : xmin;
  std::size_t last_thick = 0;
  int thin_run = 0;
  for (std::size_t c = 0; c < columns; ++c) {
    if (volume[c] >= full) {
      last_thick = c;
      thin_run = 0;
    } else if (xmin + c * dx >= gaps_from_x && ++thin_run >= 2) {
      break;
    }
  }
  return std::min(xmax, xmin + (last_thick + 1) * dx);
}

template <int Dim>
ParticleSnapshot make_snapshot(const Particles<Dim>& P, const SceneConfig& scene, const CappedVonMisesParams& plastic,
                               double time, const Bed* bed, const GateRecorder<Dim>* gate) {
  ParticleSnapshot s;
  s.dim = Dim;
  s.time_s = time;
  s.dx_m = scene.dx;
  s.softening_zeta = plastic.softening_zeta;
  s.tensile_strength_pa = scene.tensile_strength;
  s.ice_thickness_m = scene.ice_thickness;
  s.step_top_x_m = scene.step_top_x();
  s.step_foot_x_m = scene.step_foot_x();
  s.ice_front_x_m = ice_front_x(P, scene, 0.25);
  if (!P.x_ref.empty()) {
    const double top = scene.step_top_x();
    for (std::size_t p = 0; p < P.size(); ++p)
      if (P.x_ref[p][0] < top) s.upstream_ice_front_x_m = std::max(s.upstream_ice_front_x_m, P.x[p][0]);
  }
  s.particle_spacing_m = scene.dx / scene.particles_per_cell_axis;
  if (bed) s.bed_profile = bed->vertices();
  const std::size_t n = P.size();
  s.x.resize(n); s.z.resize(n); s.vx.resize(n); s.vz.resize(n);
  if (Dim == 3) { s.y.resize(n); s.vy.resize(n); }
  s.eps_v_p.assign(n, 0.0);
  s.pressure_pa.resize(n); s.von_mises_pa.resize(n); s.sigma_zz_pa.resize(n); s.volume_m3.resize(n);
  constexpr int z = up_axis<Dim>;
  for (std::size_t p = 0; p < n; ++p) {
    s.x[p] = P.x[p][0];
    s.z[p] = P.x[p][z];
    s.vx[p] = P.v[p][0];
    s.vz[p] = P.v[p][z];
    if constexpr (Dim == 3) { s.y[p] = P.x[p][1]; s.vy[p] = P.v[p][1]; }
    const double eps = P.has_plastic_state() ? P.eps_v_p[p] : 0.0;
    s.eps_v_p[p] = eps;
    s.pressure_pa[p] = pressure_of<Dim>(P.tau[p]);
    s.von_mises_pa[p] = von_mises_of<Dim>(P.tau[p]);
    const double j_e = P.F_e[p].determinant();
    // Cauchy σ = V0 τ / V: the force of a particle is V0 τ (MLS) and V = V0 J_E J_P.
    s.sigma_zz_pa[p] = P.tau[p](z, z) / (j_e * std::exp(eps));
    s.volume_m3[p] = P.vol0[p] * j_e * std::exp(eps);  // J = J_E J_P, J_P = exp(ε_v^p)
  }
  if (gate) gate->add_to(s, P);
  return s;
}

#define CREVASSE_READOUTS(D)                                                                          \
  template double total_mass<D>(const Particles<D>&);                                                 \
  template Vec<D> total_momentum<D>(const Particles<D>&);                                             \
  template double kinetic_energy<D>(const Particles<D>&);                                             \
  template double gravitational_potential_energy<D>(const Particles<D>&, double);                     \
  template double cap_dissipated_energy<D>(const Particles<D>&, const CappedVonMisesParams&);         \
  template double max_yield_violation<D>(const Particles<D>&, const CappedVonMisesParams&);           \
  template double ice_front_x<D>(const Particles<D>&, const SceneConfig&, double);                    \
  template ParticleSnapshot make_snapshot<D>(const Particles<D>&, const SceneConfig&,                 \
                                             const CappedVonMisesParams&, double, const Bed*,         \
                                             const GateRecorder<D>*);
CREVASSE_READOUTS(2)
CREVASSE_READOUTS(3)
#undef CREVASSE_READOUTS

}  // namespace crevasse
