#pragma once
// The dimensionless cohesion and the lengths it stands for, defined once: the study loader,
// the measurement's resolution rule, the case views and the calibration all use these.

namespace crevasse {

// Π = c/(ρ_i g H_i): the ice's tensile strength against the overburden at the bed.
inline double cohesion_ratio(double tensile_strength, double density, double gravity, double thickness) {
  return tensile_strength / (density * gravity * thickness);
}

// A stress given relative to the overburden ρ_i g H_i (Π for c, q_y/(ρ_i g H_i) for q_y) [Pa].
inline double stress_from_overburden_ratio(double ratio, double density, double gravity, double thickness) {
  return ratio * density * gravity * thickness;
}

// c/(ρ_i g) [m]: how deep, and how far apart, the crevasses of the strength regime are.
inline double strength_length(double tensile_strength, double density, double gravity) {
  return tensile_strength / (density * gravity);
}

}  // namespace crevasse
