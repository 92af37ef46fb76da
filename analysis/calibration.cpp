#include "engine/groups.hpp"
#include "analysis/calibration.hpp"

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_statistics_double.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace crevasse::analysis {
namespace {

std::string format(double value) {
  std::ostringstream out;
  out.precision(4);
  out << value;
  return out.str();
}

void require_positive_finite(double value, const std::string& what) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw std::invalid_argument(what + " must be a positive, finite number, got " + format(value));
  }
}

// Quartiles q25 = m·e^(−0.6745 σ_lo), q75 = m·e^(0.6745 σ_hi) of a split normal in ln L:
// the spread of the observation, asymmetric when the quartiles are.
constexpr double kNormalQuartile = 0.6744897501960817;

struct LogSpread {
  double below = 0.0;
  double above = 0.0;
};

LogSpread observation_spread(const SpacingObservation& observation) {
  require_positive_finite(observation.spacing_m, "observed spacing L_p [m]");
  if (observation.spacing_q25_m.has_value() != observation.spacing_q75_m.has_value()) {
    throw std::invalid_argument(
        "observed spacing: give both quartiles (q25 and q75) or neither; got only one");
  }
  if (observation.thickness_m)
    require_positive_finite(*observation.thickness_m, "thickness H_i [m]");
  if (!observation.spacing_q25_m) return {};
  const double q25 = *observation.spacing_q25_m, q75 = *observation.spacing_q75_m;
  require_positive_finite(q25, "spacing lower quartile q25 [m]");
  require_positive_finite(q75, "spacing upper quartile q75 [m]");
  if (!(q25 <= observation.spacing_m && observation.spacing_m <= q75)) {
    throw std::invalid_argument(
        "observed spacing: quartiles must bracket the median, got q25 = " + format(q25) +
        " m, median = " + format(observation.spacing_m) + " m, q75 = " + format(q75) + " m");
  }
  return {std::log(observation.spacing_m / q25) / kNormalQuartile,
          std::log(q75 / observation.spacing_m) / kNormalQuartile};
}

struct GslRngDeleter {
  void operator()(gsl_rng* rng) const { gsl_rng_free(rng); }
};

// The law's parameters are uncertain as a bivariate Student t (the fit's covariance, its
// residual dof); the shared scale factor also scales the law's scatter.
struct LawSampler {
  const PowerLaw& law;
  double log_a_sd_given_b1 = 0.0;  // used when b is held at 1

  // Returns (ln a, b, scatter ε) for one draw.
  std::array<double, 3> draw(gsl_rng* rng, bool hold_b_at_one, bool with_scatter,
                             double log_a_given_b1) const {
    const double scale = std::sqrt(law.dof / gsl_ran_chisq(rng, law.dof));
    const double z1 = gsl_ran_gaussian_ziggurat(rng, 1.0);
    const double z2 = gsl_ran_gaussian_ziggurat(rng, 1.0);
    const double z3 = gsl_ran_gaussian_ziggurat(rng, 1.0);
    const double scatter = with_scatter ? scale * std::sqrt(law.residual_variance) * z3 : 0.0;
    if (hold_b_at_one) return {log_a_given_b1 + scale * log_a_sd_given_b1 * z1, 1.0, scatter};
    // Cholesky factor of [[var ln a, cov], [cov, var b]].
    const double l11 = std::sqrt(std::max(law.covariance[0], 0.0));
    const double l21 = l11 > 0.0 ? law.covariance[1] / l11 : 0.0;
    const double l22 = std::sqrt(std::max(law.covariance[2] - l21 * l21, 0.0));
    return {law.log_a + scale * l11 * z1, law.b + scale * (l21 * z1 + l22 * z2), scatter};
  }
};

ConfidenceInterval percentile_interval(std::vector<double>& samples, double level) {
  std::sort(samples.begin(), samples.end());
  const double tail = 0.5 * (1.0 - level);
  return {gsl_stats_quantile_from_sorted_data(samples.data(), 1, samples.size(), tail),
          gsl_stats_quantile_from_sorted_data(samples.data(), 1, samples.size(), 1.0 - tail)};
}

}  // namespace

double cohesion_ratio(double tensile_strength_pa, double thickness_m, const IceConstants& ice) {
  return crevasse::cohesion_ratio(tensile_strength_pa, ice.density_kg_m3, ice.gravity_m_s2, thickness_m);
}

RegimeLaw regime_from_fit(std::string name, const PowerLawFit& spacing_fit,
                          std::optional<PowerLaw> depth) {
  RegimeLaw regime;
  regime.name = std::move(name);
  regime.pi_min = spacing_fit.x_min;
  regime.pi_max = spacing_fit.x_max;
  regime.spacing_ratio_min = spacing_fit.y_min;
  regime.spacing_ratio_max = spacing_fit.y_max;
  regime.spacing = spacing_fit.law;
  regime.depth = std::move(depth);
  return regime;
}

std::vector<RegimeLaw> regimes_from_broken_line(const BrokenLineFit& spacing_fit,
                                                const std::string& name_below,
                                                const std::string& name_above) {
  std::vector<RegimeLaw> regimes(2);
  for (int s = 0; s < 2; ++s) {
    RegimeLaw& regime = regimes[s];
    regime.name = s == 0 ? name_below : name_above;
    // The regimes meet at Π*: below it the lower segment holds up to Π*, above it from Π*.
    regime.pi_min = s == 0 ? spacing_fit.segment_x_min[0] : spacing_fit.breakpoint;
    regime.pi_max = s == 0 ? spacing_fit.breakpoint : spacing_fit.segment_x_max[1];
    regime.spacing_ratio_min = spacing_fit.segment_y_min[s];
    regime.spacing_ratio_max = spacing_fit.segment_y_max[s];
    regime.spacing = spacing_fit.segments[s];
  }
  return regimes;
}

CrevassePrediction predict_crevasses(const RegimeLaw& regime, double tensile_strength_pa,
                                     double thickness_m, const CalibrationOptions& options) {
  require_positive_finite(tensile_strength_pa, "tensile strength c [Pa]");
  require_positive_finite(thickness_m, "thickness H_i [m]");
  const double pi = cohesion_ratio(tensile_strength_pa, thickness_m, options.ice);
  if (pi < regime.pi_min || pi > regime.pi_max) {
    throw std::out_of_range("Π = c/(ρ g H) = " + format(pi) + " lies outside [" +
                            format(regime.pi_min) + ", " + format(regime.pi_max) +
                            "], the range regime '" + regime.name +
                            "' was fitted on; the law is not extrapolated — extend the study's "
                            "Π range or choose the regime that covers it");
  }
  CrevassePrediction prediction;
  prediction.regime = regime.name;
  prediction.cohesion_ratio_pi = pi;
  const auto scaled = [&](const ConfidenceInterval& ratio) {
    return ConfidenceInterval{ratio.lower * thickness_m, ratio.upper * thickness_m};
  };
  prediction.spacing_m = {regime.spacing.value(pi) * thickness_m,
                          scaled(regime.spacing.confidence_band(pi, options.level))};
  prediction.spacing_prediction_m = scaled(regime.spacing.prediction_band(pi, options.level));
  if (regime.depth) {
    prediction.depth_m =
        ValueWithInterval{regime.depth->value(pi) * thickness_m,
                          scaled(regime.depth->confidence_band(pi, options.level))};
    prediction.depth_prediction_m = scaled(regime.depth->prediction_band(pi, options.level));
  }
  return prediction;
}

CohesionEstimate invert_spacing_for_cohesion(const RegimeLaw& regime,
                                             const SpacingObservation& observation,
                                             const CalibrationOptions& options) {
  const LogSpread spread = observation_spread(observation);
  if (options.monte_carlo_samples < 100) {
    throw std::invalid_argument(
        "calibration: monte_carlo_samples must be at least 100 for a "
        "percentile interval, got " +
        std::to_string(options.monte_carlo_samples));
  }
  const PowerLaw& law = regime.spacing;
  const double t = student_t_quantile(options.level, law.dof);
  const double se_b = std::sqrt(law.covariance[2]);
  const std::string b_text = "b = " + format(law.b) + " ± " + format(t * se_b);
  if (std::abs(law.b) <= t * se_b) {
    throw std::domain_error("regime '" + regime.name + "': the spacing exponent " + b_text +
                            " is consistent with 0, so spacing does not depend on Π there and "
                            "cannot constrain the tensile strength c");
  }
  const double rho_g = options.ice.density_kg_m3 * options.ice.gravity_m_s2;
  CohesionEstimate estimate;
  estimate.regime = regime.name;
  estimate.level = options.level;
  estimate.notes.push_back("assumes the site is in regime '" + regime.name + "' (Π in [" +
                           format(regime.pi_min) + ", " + format(regime.pi_max) + "])");

  const bool have_thickness = observation.thickness_m.has_value();
  // Without H_i, L_p = a·c/(ρ g)·H_i^(1−b): only b = 1 removes H_i. Hold b at 1 and use ln a
  // conditional on b = 1 (the least-squares fit with b fixed at 1, for a straight-line fit).
  double log_a_given_b1 = 0.0, log_a_sd_given_b1 = 0.0;
  if (!have_thickness) {
    if (std::abs(law.b - 1.0) > t * se_b) {
      throw std::domain_error(
          "regime '" + regime.name +
          "': ice thickness H_i is needed to invert the spacing, "
          "because L_p = a·c/(ρ g)·H_i^(1−b) depends on H_i unless b = 1, and the fitted " +
          b_text + " excludes 1; give the thickness at the site");
    }
    // A user-fixed exponent has no variance: then b = 1 already and ln a is unchanged.
    const double slope = law.covariance[2] > 0.0 ? law.covariance[1] / law.covariance[2] : 0.0;
    log_a_given_b1 = law.log_a + slope * (1.0 - law.b);
    log_a_sd_given_b1 = std::sqrt(std::max(law.covariance[0] - law.covariance[1] * slope, 0.0));
    estimate.thickness_independent = true;
    estimate.notes.push_back("H_i not given: the exponent " + b_text +
                             " is consistent with 1, so L_p = a·c/(ρ_i g) was used with b held "
                             "at 1; whether the site's Π lies in the regime cannot be checked "
                             "without H_i");
  } else {
    const double ratio = observation.spacing_m / *observation.thickness_m;
    if (ratio < regime.spacing_ratio_min || ratio > regime.spacing_ratio_max) {
      throw std::out_of_range(
          "L_p/H_i = " + format(ratio) + " lies outside [" + format(regime.spacing_ratio_min) +
          ", " + format(regime.spacing_ratio_max) +
          "], the spacings the study "
          "produced in regime '" +
          regime.name + "'; c is not extrapolated — extend the study or check the regime");
    }
  }

  // c from ln(L_p/H_i) = ln a + b·ln Π + ε, solved for Π; with b = 1 and no H_i,
  // ln L_p = ln a + ln(c/(ρ g)) + ε.
  const double log_h = have_thickness ? std::log(*observation.thickness_m) : 0.0;
  const auto cohesion = [&](double log_spacing, double log_a, double b, double scatter) {
    if (!have_thickness) return rho_g * std::exp(log_spacing - scatter - log_a);
    const double log_pi = (log_spacing - log_h - scatter - log_a) / b;
    return stress_from_overburden_ratio(std::exp(log_pi), options.ice.density_kg_m3, options.ice.gravity_m_s2,
                                        *observation.thickness_m);
  };
  const double log_spacing = std::log(observation.spacing_m);
  estimate.tensile_strength_pa = have_thickness ? cohesion(log_spacing, law.log_a, law.b, 0.0)
                                                : cohesion(log_spacing, log_a_given_b1, 1.0, 0.0);

  // Monte Carlo propagation (fixed seed, GSL's MT19937 so the stream is the same everywhere).
  std::unique_ptr<gsl_rng, GslRngDeleter> rng(gsl_rng_alloc(gsl_rng_mt19937));
  gsl_rng_set(rng.get(), static_cast<unsigned long>(options.seed));
  const LawSampler sampler{law, log_a_sd_given_b1};
  std::vector<double> samples(options.monte_carlo_samples);
  for (double& sample : samples) {
    const auto [log_a, b, scatter] =
        sampler.draw(rng.get(), !have_thickness, options.include_law_scatter, log_a_given_b1);
    const double z = gsl_ran_gaussian_ziggurat(rng.get(), 1.0);
    const double log_l = log_spacing + z * (z < 0.0 ? spread.below : spread.above);
    sample = cohesion(log_l, log_a, b, scatter);
  }
  estimate.interval_pa = percentile_interval(samples, options.level);
  if (observation.spacing_q25_m) {
    estimate.notes.push_back(
        "the quartile spread of the observed spacings is taken as the "
        "uncertainty of the median spacing (conservative)");
  }
  if (options.include_law_scatter) {
    estimate.notes.push_back("the interval includes the study's scatter about the law");
  }

  if (have_thickness) {
    const auto pi_of = [&](double c) { return cohesion_ratio(c, *observation.thickness_m, options.ice); };
    const ValueWithInterval pi{pi_of(estimate.tensile_strength_pa),
                               {pi_of(estimate.interval_pa.lower), pi_of(estimate.interval_pa.upper)}};
    estimate.cohesion_ratio_pi = pi;
    estimate.pi_in_regime_range = regime.pi_min <= pi.value && pi.value <= regime.pi_max;
    estimate.pi_interval_in_regime_range =
        regime.pi_min <= pi.interval.lower && pi.interval.upper <= regime.pi_max;
    if (!*estimate.pi_in_regime_range) {
      estimate.notes.push_back("the estimated Π = " + format(pi.value) + " lies outside regime '" +
                               regime.name + "': the assumed regime is not self-consistent");
    }
  }
  return estimate;
}

std::vector<CohesionEstimate> invert_spacing_in_all_regimes(const std::vector<RegimeLaw>& regimes,
                                                            const SpacingObservation& observation,
                                                            const CalibrationOptions& options) {
  std::vector<CohesionEstimate> estimates;
  std::string refusals;
  for (const RegimeLaw& regime : regimes) {
    try {
      estimates.push_back(invert_spacing_for_cohesion(regime, observation, options));
    } catch (const std::out_of_range& e) {
      refusals += std::string("\n  ") + e.what();
    } catch (const std::domain_error& e) {
      refusals += std::string("\n  ") + e.what();
    }
  }
  if (estimates.empty()) {
    throw std::out_of_range(
        "no regime of the study can invert this observation:" +
        (refusals.empty() ? std::string(" the study has no regimes") : refusals));
  }
  return estimates;
}

}  // namespace crevasse::analysis
