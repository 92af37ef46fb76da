#pragma once
// Calibration (docs/fits.md §5): the study's laws L_p/H_i = a·Π^b and D_p/H_i = a·Π^b with
// Π = c/(ρ_i g H_i), used forwards (predict spacing and depth for a given c and H_i) and
// backwards (estimate the tensile strength c from an observed crevasse spacing). Method and
// assumptions: docs/fits.md.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "analysis/broken_line_fit.hpp"
#include "analysis/power_law_fit.hpp"

namespace crevasse::analysis {

struct IceConstants {
  double density_kg_m3 = 917.0;  // ρ_i
  double gravity_m_s2 = 9.81;    // g
};

// Π = c/(ρ_i g H_i).
double cohesion_ratio(double tensile_strength_pa, double thickness_m, const IceConstants& ice = {});

// One regime of a fitted study: where it holds and the laws that hold there.
struct RegimeLaw {
  std::string name;                   // e.g. "strength-limited (Π < Π*)"
  double pi_min = 0.0, pi_max = 0.0;  // Π range the study covered in this regime
  // L_p/H_i range the study observed in this regime: an inversion outside it is refused.
  double spacing_ratio_min = 0.0, spacing_ratio_max = 0.0;
  PowerLaw spacing;               // L_p/H_i = a·Π^b
  std::optional<PowerLaw> depth;  // D_p/H_i = a·Π^b, when fitted
};

// A single power-law fit of L_p/H_i against Π as one regime covering its data.
RegimeLaw regime_from_fit(std::string name, const PowerLawFit& spacing_fit,
                          std::optional<PowerLaw> depth = std::nullopt);
// The two segments of a broken-line fit of L_p/H_i against Π as two regimes, split at Π*.
std::vector<RegimeLaw> regimes_from_broken_line(const BrokenLineFit& spacing_fit,
                                                const std::string& name_below = "below Π*",
                                                const std::string& name_above = "above Π*");

struct CalibrationOptions {
  IceConstants ice;
  double level = 0.95;
  std::size_t monte_carlo_samples = 20000;
  std::uint64_t seed = 20240601;  // fixed: the same inputs always give the same interval
  // Add the study's scatter about the law (s² of the fit) to the uncertainty: the law gives
  // the typical spacing for a c, one site may sit off it as the simulated cases do.
  bool include_law_scatter = true;
};

struct ValueWithInterval {
  double value = 0.0;
  ConfidenceInterval interval;
};

struct CrevassePrediction {
  std::string regime;
  double cohesion_ratio_pi = 0.0;
  // Median spacing/depth [m]: `confidence` bounds the law (fit uncertainty only), `prediction`
  // adds the study's scatter about it (where one site's value is expected to fall).
  ValueWithInterval spacing_m;
  ConfidenceInterval spacing_prediction_m;
  std::optional<ValueWithInterval> depth_m;
  std::optional<ConfidenceInterval> depth_prediction_m;
};

// Spacing (and depth, when the regime has a depth law) for tensile strength c and thickness H_i.
// Throws std::out_of_range when Π falls outside the regime's range (no extrapolation).
CrevassePrediction predict_crevasses(const RegimeLaw& regime, double tensile_strength_pa,
                                     double thickness_m, const CalibrationOptions& options = {});

struct SpacingObservation {
  double spacing_m = 0.0;  // median observed crevasse spacing L_p
  // Quartiles of the observed spacings: the spread of the observation. Both or neither.
  std::optional<double> spacing_q25_m;
  std::optional<double> spacing_q75_m;
  std::optional<double> thickness_m;  // H_i at the site, when known
};

struct CohesionEstimate {
  std::string regime;                // the regime whose law was inverted
  double tensile_strength_pa = 0.0;  // c from the medians of all inputs
  ConfidenceInterval interval_pa;    // Monte Carlo percentile interval at `level`
  double level = 0.95;
  // Π = c/(ρ g H) and its interval, and whether they lie in the regime's Π range. Empty when
  // H_i was not given.
  std::optional<ValueWithInterval> cohesion_ratio_pi;
  std::optional<bool> pi_in_regime_range;
  std::optional<bool> pi_interval_in_regime_range;
  // True when H_i was not given and the regime's exponent is 1 within its interval, so that
  // L_p = a·c/(ρ g) and the law was refitted with b = 1.
  bool thickness_independent = false;
  std::vector<std::string> notes;  // assumptions a user should read
};

// Inverts the regime's spacing law for c. Throws std::invalid_argument for a bad observation
// (non-positive or non-finite values, quartiles not around the median, only one quartile),
// std::domain_error when the law cannot give c (exponent consistent with 0; H_i missing and
// the exponent not consistent with 1), and std::out_of_range when L_p/H_i lies outside the
// range the study covered in this regime.
CohesionEstimate invert_spacing_for_cohesion(const RegimeLaw& regime,
                                             const SpacingObservation& observation,
                                             const CalibrationOptions& options = {});

// Inverts in every regime whose L_p/H_i range holds the observation; regimes that refuse are
// skipped. Throws std::out_of_range listing the ranges when no regime accepts it. The
// pi_in_regime_range flags say which answer is self-consistent.
std::vector<CohesionEstimate> invert_spacing_in_all_regimes(const std::vector<RegimeLaw>& regimes,
                                                            const SpacingObservation& observation,
                                                            const CalibrationOptions& options = {});

}  // namespace crevasse::analysis
