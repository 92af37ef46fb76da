#include "analysis/bed_contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "engine/bed.hpp"

namespace crevasse::analysis {

BedContact bed_contact(const ParticleSnapshot& s, double x_min, double x_max) {
  if (s.bed_profile.size() < 2) throw std::invalid_argument("bed contact: the snapshot has no bed profile");
  if (!(s.dx_m > 0.0)) throw std::invalid_argument("bed contact: the snapshot has no dx");
  BedContact c;
  if (!(x_max > x_min)) return c;
  const Bed bed = Bed::polyline(s.bed_profile);
  const double dx = s.dx_m;
  c.columns = static_cast<std::size_t>(std::ceil((x_max - x_min) / dx));
  const double half_spacing = 0.5 * (s.particle_spacing_m > 0.0 ? s.particle_spacing_m : 0.5 * dx);
  std::vector<double> lowest(c.columns, std::numeric_limits<double>::infinity());
  for (std::size_t p = 0; p < s.x.size(); ++p) {
    if (s.x[p] < x_min || s.x[p] >= x_max) continue;
    const auto i = std::min(c.columns - 1, static_cast<std::size_t>((s.x[p] - x_min) / dx));
    lowest[i] = std::min(lowest[i], s.z[p] - bed.height_at(s.x[p]));
  }
  bool any = false;
  for (std::size_t i = 0; i < c.columns; ++i) {
    if (!std::isfinite(lowest[i])) {
      ++c.empty_columns;
      continue;
    }
    const double gap = std::max(0.0, lowest[i] - half_spacing);
    if (!any || gap > c.max_gap_m) {
      c.max_gap_m = gap;
      c.max_gap_x_m = x_min + (static_cast<double>(i) + 0.5) * dx;
      any = true;
    }
  }
  return c;
}

BedContact ramp_contact(const ParticleSnapshot& s) {
  return bed_contact(s, s.step_top_x_m, s.step_foot_x_m);
}

}  // namespace crevasse::analysis
