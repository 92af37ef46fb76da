#include "analysis/damage_criterion.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace crevasse::analysis {

DamageCriterion::DamageCriterion(double softening_zeta, double damage_threshold,
                                 double eps_v_p_threshold) {
  if (!(damage_threshold > 0.0 && damage_threshold < 1.0)) {
    throw std::invalid_argument(
        "damage threshold must lie in (0, 1) (fraction of strength lost), got " +
        std::to_string(damage_threshold));
  }
  if (!(softening_zeta >= 0.0) || !std::isfinite(softening_zeta)) {
    throw std::invalid_argument("softening zeta must be finite and >= 0, got " +
                                std::to_string(softening_zeta));
  }
  // Strength left is exp(−ζ ε); "threshold lost" ⇔ ε ≥ −ln(1 − threshold)/ζ.
  const double log_remaining = -std::log1p(-damage_threshold);
  uses_softening_ = softening_zeta > 0.0;
  if (uses_softening_) {
    zeta_effective_ = softening_zeta;
    eps_v_p_at_threshold_ = log_remaining / softening_zeta;
  } else {
    if (!(eps_v_p_threshold > 0.0) || !std::isfinite(eps_v_p_threshold)) {
      throw std::invalid_argument(
          "the snapshot has no softening (zeta = 0), so damage needs an absolute eps_v_p "
          "threshold > 0; got " +
          std::to_string(eps_v_p_threshold));
    }
    eps_v_p_at_threshold_ = eps_v_p_threshold;
    zeta_effective_ = log_remaining / eps_v_p_threshold;
  }
}

DamageCriterion DamageCriterion::for_snapshot(const ParticleSnapshot& snapshot,
                                              double damage_threshold, double eps_v_p_threshold) {
  return DamageCriterion(snapshot.softening_zeta, damage_threshold, eps_v_p_threshold);
}

double DamageCriterion::level(double eps_v_p) const {
  if (!(eps_v_p > 0.0)) return 0.0;  // also maps NaN to intact rather than propagating it
  return -std::expm1(-zeta_effective_ * eps_v_p);
}

}  // namespace crevasse::analysis
