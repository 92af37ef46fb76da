#include "analysis/surface_profile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

namespace crevasse::analysis {

double SurfaceProfile::height_at(double x_m) const {
  if (z_m.empty()) return 0.0;
  const double u = (x_m - x0_m) / bin_width_m - 0.5;  // fractional bin-centre index
  if (!(u > 0.0)) return z_m.front();
  const auto last = static_cast<double>(z_m.size() - 1);
  if (u >= last) return z_m.back();
  const auto i = static_cast<std::size_t>(u);
  const double t = u - static_cast<double>(i);
  return (1.0 - t) * z_m[i] + t * z_m[i + 1];
}

namespace {

constexpr double kMissing = -std::numeric_limits<double>::infinity();

// Highest particle per bin, among those for which `use` is true.
std::vector<double> top_per_bin(std::span<const double> x, std::span<const double> z, double x0,
                                double width, std::size_t n_bins, auto use) {
  std::vector<double> top(n_bins, kMissing);
  for (std::size_t p = 0; p < x.size(); ++p) {
    if (!use(p)) continue;
    auto b = static_cast<std::size_t>(std::max(0.0, std::floor((x[p] - x0) / width)));
    b = std::min(b, n_bins - 1);
    top[b] = std::max(top[b], z[p]);
  }
  return top;
}

// Local upper envelope by chords: z_i ← max(z_i, chords between measured bins a < i < b within
// ±w bins). A crevasse dip sits below the chord joining its lips and is lifted to it; a
// straight or convex surface lies on or above every such chord and is unchanged.
std::vector<double> bridge_dips(const std::vector<double>& top, std::size_t w, const std::function<void()>& poll) {
  const std::size_t n = top.size();
  std::vector<double> out = top;
  for (std::size_t i = 1; i + 1 < n; ++i) {
    if (poll && i % 256 == 0) poll();
    const std::size_t a0 = i >= w ? i - w : 0;
    const std::size_t b1 = std::min(n - 1, i + w);
    for (std::size_t a = a0; a < i; ++a) {
      if (top[a] == kMissing) continue;
      for (std::size_t b = i + 1; b <= b1; ++b) {
        if (top[b] == kMissing) continue;
        const double t = static_cast<double>(i - a) / static_cast<double>(b - a);
        out[i] = std::max(out[i], (1.0 - t) * top[a] + t * top[b]);
      }
    }
  }
  return out;
}

// Linear interpolation over the remaining missing bins; constant extension past the ends.
void fill_missing(std::vector<double>& z) {
  std::optional<std::size_t> last_known;
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (z[i] == kMissing) continue;
    if (!last_known) {
      for (std::size_t k = 0; k < i; ++k) z[k] = z[i];
    } else if (*last_known + 1 < i) {
      const std::size_t a = *last_known;
      for (std::size_t k = a + 1; k < i; ++k) {
        const double t = static_cast<double>(k - a) / static_cast<double>(i - a);
        z[k] = (1.0 - t) * z[a] + t * z[i];
      }
    }
    last_known = i;
  }
  if (last_known) {
    for (std::size_t k = *last_known + 1; k < z.size(); ++k) z[k] = z[*last_known];
  }
}

std::vector<double> moving_average(const std::vector<double>& z, int bins) {
  if (bins <= 1) return z;
  const auto half = static_cast<std::size_t>(bins / 2);
  std::vector<double> out(z.size());
  for (std::size_t i = 0; i < z.size(); ++i) {
    const std::size_t a = i >= half ? i - half : 0;
    const std::size_t b = std::min(z.size() - 1, i + half);
    double sum = 0.0;
    for (std::size_t k = a; k <= b; ++k) sum += z[k];
    out[i] = sum / static_cast<double>(b - a + 1);
  }
  return out;
}

}  // namespace

SurfaceProfile compute_surface_profile(std::span<const double> x, std::span<const double> z,
                                       std::span<const std::uint8_t> damaged,
                                       const SurfaceSettings& settings) {
  if (x.size() != z.size() || x.size() != damaged.size()) {
    throw std::invalid_argument("surface profile: x, z and damage arrays differ in length (" +
                                std::to_string(x.size()) + ", " + std::to_string(z.size()) + ", " +
                                std::to_string(damaged.size()) + ")");
  }
  if (!(settings.bin_width_m > 0.0) || !std::isfinite(settings.bin_width_m)) {
    throw std::invalid_argument("surface profile: bin width must be > 0 m (set it to dx), got " +
                                std::to_string(settings.bin_width_m));
  }
  SurfaceProfile profile;
  profile.bin_width_m = settings.bin_width_m;
  if (x.empty()) return profile;

  const auto [x_lo, x_hi] = std::minmax_element(x.begin(), x.end());
  profile.x0_m = std::floor(*x_lo / settings.bin_width_m) * settings.bin_width_m;
  const auto n_bins =
      static_cast<std::size_t>(std::floor((*x_hi - profile.x0_m) / settings.bin_width_m) + 1.0);

  const bool any_intact = std::find(damaged.begin(), damaged.end(), 0) != damaged.end();
  std::vector<double> top = any_intact
                                ? top_per_bin(x, z, profile.x0_m, settings.bin_width_m, n_bins,
                                              [&](std::size_t p) { return damaged[p] == 0; })
                                : top_per_bin(x, z, profile.x0_m, settings.bin_width_m, n_bins,
                                              [](std::size_t) { return true; });
  profile.measured.resize(n_bins);
  for (std::size_t i = 0; i < n_bins; ++i) profile.measured[i] = top[i] != kMissing ? 1 : 0;

  const auto w = static_cast<std::size_t>(
      std::max(1.0, std::ceil(settings.bridge_half_width_m / settings.bin_width_m)));
  std::vector<double> bridged = bridge_dips(top, w, settings.poll);
  for (std::size_t i = 0; i < n_bins; ++i) {
    // A micrometre margin keeps round-off on a straight slope from counting as a bridged dip.
    if (top[i] != kMissing && bridged[i] > top[i] + 1e-6) profile.measured[i] = 0;
  }
  fill_missing(bridged);
  profile.z_m = moving_average(bridged, settings.smoothing_bins);
  for (double& v : profile.z_m) v += settings.particle_half_extent_m;
  return profile;
}

}  // namespace crevasse::analysis
