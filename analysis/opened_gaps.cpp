#include "analysis/opened_gaps.hpp"

#include <algorithm>
#include <cmath>

namespace crevasse::analysis {
namespace {

double bed_at(const std::vector<std::array<double, 2>>& bed, double x) {
  if (x <= bed.front()[0]) return bed.front()[1];
  if (x >= bed.back()[0]) return bed.back()[1];
  const auto hi = std::upper_bound(bed.begin(), bed.end(), x,
                                   [](double v, const std::array<double, 2>& p) { return v < p[0]; });
  const auto lo = hi - 1;
  const double t = ((*hi)[0] > (*lo)[0]) ? (x - (*lo)[0]) / ((*hi)[0] - (*lo)[0]) : 0.0;
  return (*lo)[1] + t * ((*hi)[1] - (*lo)[1]);
}

}  // namespace

GapPoints find_opened_gaps(std::span<const double> x, std::span<const double> z,
                           std::span<const std::uint8_t> damaged, const SurfaceProfile& surface,
                           const std::vector<std::array<double, 2>>& bed, double dx_m, double particle_spacing_m) {
  GapPoints out;
  if (x.empty() || surface.size() == 0 || !(dx_m > 0.0)) return out;
  const double z_low = *std::min_element(z.begin(), z.end());
  const double z0 = std::floor(z_low / dx_m) * dx_m - dx_m;
  const double z_top = *std::max_element(z.begin(), z.end());
  const auto nx = surface.size();
  const auto nz = static_cast<std::size_t>(std::ceil((z_top - z0) / dx_m)) + 2;
  std::vector<std::uint32_t> count(nx * nz, 0);
  std::vector<std::uint8_t> has_damaged(nx * nz, 0);
  for (std::size_t p = 0; p < x.size(); ++p) {
    const double fx = std::floor((x[p] - surface.x0_m) / dx_m), fz = std::floor((z[p] - z0) / dx_m);
    if (fx < 0 || fx >= static_cast<double>(nx) || fz < 0 || fz >= static_cast<double>(nz)) continue;
    const std::size_t cell = static_cast<std::size_t>(fx) * nz + static_cast<std::size_t>(fz);
    ++count[cell];
    if (damaged[p]) has_damaged[cell] = 1;
  }
  const bool has_bed = bed.size() >= 2;
  // Empty cells inside the ice.
  std::vector<std::uint8_t> gap(nx * nz, 0);
  for (std::size_t i = 0; i < nx; ++i) {
    const double x_lo = surface.x0_m + static_cast<double>(i) * dx_m, x_hi = x_lo + dx_m;
    const double roof = std::min(surface.height_at(x_lo), surface.height_at(x_hi));
    const double floor_z = has_bed ? std::max(bed_at(bed, x_lo), bed_at(bed, x_hi)) : z_low;
    for (std::size_t k = 0; k < nz; ++k) {
      const double z_lo = z0 + static_cast<double>(k) * dx_m;
      if (z_lo >= floor_z && z_lo + dx_m <= roof && count[i * nz + k] == 0) gap[i * nz + k] = 1;
    }
  }
  // Patches of gap cells (side-connected), each kept whole when one of its cells has a damaged
  // particle in a neighbouring cell (corners included).
  const auto ix = [nz](std::size_t c) { return c / nz; };
  const auto iz = [nz](std::size_t c) { return c % nz; };
  std::vector<std::uint8_t> seen(nx * nz, 0);
  std::vector<std::size_t> patch, stack;
  const int per_axis = std::max(1, static_cast<int>(std::lround(dx_m / particle_spacing_m)));
  const double step = dx_m / per_axis;
  for (std::size_t start = 0; start < gap.size(); ++start) {
    if (!gap[start] || seen[start]) continue;
    patch.clear();
    stack.assign(1, start);
    seen[start] = 1;
    bool borders_damage = false;
    while (!stack.empty()) {
      const std::size_t c = stack.back();
      stack.pop_back();
      patch.push_back(c);
      const auto i = static_cast<long>(ix(c)), k = static_cast<long>(iz(c));
      for (long di = -1; di <= 1; ++di)
        for (long dk = -1; dk <= 1; ++dk) {
          const long a = i + di, b = k + dk;
          if (a < 0 || b < 0 || a >= static_cast<long>(nx) || b >= static_cast<long>(nz)) continue;
          const std::size_t n = static_cast<std::size_t>(a) * nz + static_cast<std::size_t>(b);
          borders_damage = borders_damage || has_damaged[n];
          if ((di == 0) != (dk == 0) && gap[n] && !seen[n]) {
            seen[n] = 1;
            stack.push_back(n);
          }
        }
    }
    if (!borders_damage) continue;
    for (std::size_t c : patch) {
      ++out.cell_count;
      const double x_lo = surface.x0_m + static_cast<double>(ix(c)) * dx_m;
      const double z_lo = z0 + static_cast<double>(iz(c)) * dx_m;
      for (int a = 0; a < per_axis; ++a)
        for (int b = 0; b < per_axis; ++b) {
          out.x.push_back(x_lo + (a + 0.5) * step);
          out.z.push_back(z_lo + (b + 0.5) * step);
        }
    }
  }
  return out;
}

}  // namespace crevasse::analysis
