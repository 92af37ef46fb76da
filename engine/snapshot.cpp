#include "engine/snapshot.hpp"

#include <algorithm>
#include <cmath>

namespace crevasse {

double ParticleSnapshot::damage(std::size_t i) const {
  if (softening_zeta <= 0.0) return 0.0;
  return 1.0 - std::exp(-softening_zeta * eps_v_p[i]);
}

double ParticleSnapshot::front_x() const {
  if (x.empty()) return 0.0;
  if (ice_front_x_m > 0.0) return ice_front_x_m;
  return *std::max_element(x.begin(), x.end());
}

}  // namespace crevasse
