#pragma once
// When a particle counts as damaged (docs/measurement.md), and a continuous damage level for figures that
// agrees with that decision at the threshold.
#include "engine/snapshot.hpp"

namespace crevasse::analysis {

class DamageCriterion {
 public:
  // damage_threshold applies to 1 − exp(−ζ ε_v^p) and must lie in (0, 1).
  // eps_v_p_threshold (> 0) is used instead when the snapshot has no softening (ζ = 0).
  DamageCriterion(double softening_zeta, double damage_threshold, double eps_v_p_threshold);
  static DamageCriterion for_snapshot(const ParticleSnapshot& snapshot, double damage_threshold,
                                      double eps_v_p_threshold);

  // Damage level in [0, 1]: 1 − exp(−ζ ε_v^p). Without softening an equivalent rate
  // ζ_eff = −ln(1 − threshold) / ε_threshold is used, so the level crosses the damage threshold
  // exactly at ε_threshold and the colour scale of a figure means the same in both cases.
  double level(double eps_v_p) const;
  bool is_damaged(double eps_v_p) const { return eps_v_p >= eps_v_p_at_threshold_; }

  // The ε_v^p at which a particle becomes damaged: −ln(1 − threshold)/ζ, or ε_threshold.
  double eps_v_p_at_threshold() const { return eps_v_p_at_threshold_; }
  bool uses_softening() const { return uses_softening_; }

 private:
  double zeta_effective_ = 0.0;
  double eps_v_p_at_threshold_ = 0.0;
  bool uses_softening_ = false;
};

}  // namespace crevasse::analysis
