#pragma once
// Synthetic particle snapshots with crevasses of known position and depth, for the measurement
// and side-view tests: a regular lattice of spacing dx/2 (4 particles per cell in 2D), resting
// on a base z_b(x) so the surface z_b(x) + H_i can slope or curve, with "notches" = columns of
// damaged particles.
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "engine/snapshot.hpp"

namespace crevasse::test {

struct Notch {
  double x_m = 0.0;      // centre; columns within width/2 (at least the nearest one) are damaged
  double depth_m = 0.0;  // damaged from top_gap_m below the surface down to this depth
  double width_m = 0.0;
  double top_gap_m = 0.0;  // > 0: buried damage starting this far below the surface
};

struct SlabSpec {
  int dim = 2;
  double dx_m = 10.0;
  double thickness_m = 100.0;
  double x_min_m = 0.0;
  double x_max_m = 2000.0;
  double width_m = 40.0;  // 3D extent in y
  std::function<double(double)> base_z = [](double) { return 0.0; };
  double noise_over_spacing = 0.0;  // uniform ±noise·spacing on every coordinate
  unsigned seed = 12345;
  double softening_zeta = 500.0;
  // ε_v^p given to notch particles: damage 1 − e^{-10} ≫ 0.95.
  double notch_eps_v_p = 10.0 / 500.0;
};

inline double spacing_of(const SlabSpec& spec) { return 0.5 * spec.dx_m; }

inline ParticleSnapshot make_slab(const SlabSpec& spec, const std::vector<Notch>& notches) {
  ParticleSnapshot s;
  s.dim = spec.dim;
  s.time_s = 1234.5;
  s.dx_m = spec.dx_m;
  s.softening_zeta = spec.softening_zeta;
  s.tensile_strength_pa = 1.0e5;
  s.ice_thickness_m = spec.thickness_m;
  s.step_top_x_m = spec.x_min_m;
  s.step_foot_x_m = spec.x_min_m;
  const double h = spacing_of(spec);
  s.particle_spacing_m = h;
  const int nx = static_cast<int>(std::round((spec.x_max_m - spec.x_min_m) / h));
  const int nz = static_cast<int>(std::round(spec.thickness_m / h));
  const int ny = spec.dim == 3 ? static_cast<int>(std::round(spec.width_m / h)) : 1;
  for (int i = -1; i <= nx + 1; i += 1) {
    const double xb = spec.x_min_m + i * h;
    s.bed_profile.push_back({xb, spec.base_z(xb)});
  }
  std::mt19937 rng(spec.seed);
  std::uniform_real_distribution<double> noise(-spec.noise_over_spacing * h,
                                               spec.noise_over_spacing * h);
  // Nearest column to each notch, so every notch damages at least one column.
  std::vector<int> nearest(notches.size());
  for (std::size_t k = 0; k < notches.size(); ++k) {
    nearest[k] = static_cast<int>(std::floor((notches[k].x_m - spec.x_min_m) / h));
  }
  for (int i = 0; i < nx; ++i) {
    const double xc = spec.x_min_m + (i + 0.5) * h;
    const double base = spec.base_z(xc);
    const double surface = base + spec.thickness_m;
    for (int k = 0; k < nz; ++k) {
      const double zc = base + (k + 0.5) * h;
      bool damaged = false;
      for (std::size_t n = 0; n < notches.size(); ++n) {
        const Notch& notch = notches[n];
        const bool in_column = i == nearest[n] || std::abs(xc - notch.x_m) <= 0.5 * notch.width_m;
        // The particle's volume [zc − h/2, zc + h/2] lies inside the notch's depth range.
        if (in_column && zc - 0.5 * h >= surface - notch.depth_m - 1e-9 &&
            zc + 0.5 * h <= surface - notch.top_gap_m + 1e-9) {
          damaged = true;
        }
      }
      for (int j = 0; j < ny; ++j) {
        s.x.push_back(xc + noise(rng));
        s.z.push_back(zc + noise(rng));
        if (spec.dim == 3) {
          s.y.push_back((j + 0.5) * h + noise(rng));
          s.vy.push_back(0.0);
        }
        s.vx.push_back(4.0);
        s.vz.push_back(0.0);
        s.eps_v_p.push_back(damaged ? spec.notch_eps_v_p : 0.0);
        s.pressure_pa.push_back(0.0);
        s.von_mises_pa.push_back(0.0);
        s.sigma_zz_pa.push_back(0.0);
        s.volume_m3.push_back(spec.dim == 3 ? h * h * h : h * h);
      }
    }
  }
  return s;
}

}  // namespace crevasse::test
