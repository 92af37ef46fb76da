#include "analysis/power_law_fit.hpp"

#include <gsl/gsl_cdf.h>
#include <gsl/gsl_fit.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace crevasse::analysis {

LogLogData to_log_log(std::span<const double> x, std::span<const double> y, const char* what) {
  if (x.size() != y.size()) {
    throw std::invalid_argument(std::string(what) + ": x has " + std::to_string(x.size()) +
                                " values but y has " + std::to_string(y.size()) +
                                "; give one y per x");
  }
  LogLogData data;
  data.log_x.reserve(x.size());
  data.log_y.reserve(y.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const auto bad = [&](const std::string& why) {
      return std::invalid_argument(std::string(what) + ": row " + std::to_string(i) +
                                   " (x = " + std::to_string(x[i]) +
                                   ", y = " + std::to_string(y[i]) + ") " + why +
                                   "; a log-log fit needs finite, positive x and y — remove "
                                   "or fix the row (failed cases belong in the figure, not "
                                   "the fit)");
    };
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) throw bad("is not finite");
    if (x[i] <= 0.0) throw bad("has x ≤ 0");
    if (y[i] <= 0.0) throw bad("has y ≤ 0");
    data.log_x.push_back(std::log(x[i]));
    data.log_y.push_back(std::log(y[i]));
  }
  return data;
}

double student_t_quantile(double level, double dof) {
  if (!(level > 0.0 && level < 1.0)) {
    throw std::invalid_argument("confidence level must lie in (0, 1), got " +
                                std::to_string(level));
  }
  if (!(dof > 0.0)) {
    throw std::invalid_argument("a t interval needs at least one residual degree of freedom, got " +
                                std::to_string(dof) + "; add data points");
  }
  return gsl_cdf_tdist_Pinv(0.5 * (1.0 + level), dof);
}

double PowerLaw::a() const { return std::exp(log_a); }

double PowerLaw::value(double x) const { return std::exp(log_a + b * std::log(x)); }

double PowerLaw::log_value_standard_error(double x) const {
  // var(ln a + b·u) = var(ln a) + 2u·cov + u²·var(b).
  const double u = std::log(x);
  const double variance = covariance[0] + 2.0 * u * covariance[1] + u * u * covariance[2];
  return std::sqrt(std::max(variance, 0.0));
}

ConfidenceInterval PowerLaw::confidence_band(double x, double level) const {
  const double t = student_t_quantile(level, dof);
  const double centre = log_a + b * std::log(x);
  const double half = t * log_value_standard_error(x);
  return {std::exp(centre - half), std::exp(centre + half)};
}

ConfidenceInterval PowerLaw::prediction_band(double x, double level) const {
  const double t = student_t_quantile(level, dof);
  const double centre = log_a + b * std::log(x);
  const double se = log_value_standard_error(x);
  const double half = t * std::sqrt(se * se + residual_variance);
  return {std::exp(centre - half), std::exp(centre + half)};
}

double least_squares_aic(double rss, std::size_t n, std::size_t parameters) {
  // An exact fit would give −∞; the clamp keeps comparisons finite and still ranks it best.
  const double floor = std::numeric_limits<double>::min();
  const double nn = static_cast<double>(n);
  return nn * std::log(std::max(rss, floor) / nn) + 2.0 * static_cast<double>(parameters + 1);
}

PowerLawFit fit_power_law(std::span<const double> x, std::span<const double> y, double level) {
  const LogLogData data = to_log_log(x, y, "power-law fit");
  const std::size_t n = data.log_x.size();
  if (n < 3) {
    throw std::invalid_argument("power-law fit: got " + std::to_string(n) +
                                " point(s); at least 3 are needed for a fit with an "
                                "uncertainty (2 parameters + 1 residual degree of freedom)");
  }
  const auto [u_min, u_max] = std::minmax_element(data.log_x.begin(), data.log_x.end());
  if (*u_min == *u_max) {
    throw std::invalid_argument("power-law fit: all " + std::to_string(n) +
                                " points have the same x = " + std::to_string(std::exp(*u_min)) +
                                "; the exponent is undetermined — vary x (e.g. Π) in the study");
  }
  // Validate the level before GSL sees it: GSL's default error handler aborts.
  const double t = student_t_quantile(level, static_cast<double>(n - 2));

  PowerLawFit fit;
  double c0 = 0.0, c1 = 0.0, cov00 = 0.0, cov01 = 0.0, cov11 = 0.0, rss = 0.0;
  gsl_fit_linear(data.log_x.data(), 1, data.log_y.data(), 1, n, &c0, &c1, &cov00, &cov01, &cov11,
                 &rss);
  fit.level = level;
  fit.n = n;
  fit.rss = rss;
  fit.residual_variance = rss / static_cast<double>(n - 2);
  fit.law =
      PowerLaw{c0, c1, {cov00, cov01, cov11}, fit.residual_variance, static_cast<double>(n - 2)};
  fit.se_log_a = std::sqrt(cov00);
  fit.se_b = std::sqrt(cov11);
  fit.ci_a = {std::exp(c0 - t * fit.se_log_a), std::exp(c0 + t * fit.se_log_a)};
  fit.ci_b = {c1 - t * fit.se_b, c1 + t * fit.se_b};

  double mean_v = 0.0;
  for (double v : data.log_y) mean_v += v;
  mean_v /= static_cast<double>(n);
  double tss = 0.0;
  for (double v : data.log_y) tss += (v - mean_v) * (v - mean_v);
  // All y equal and fitted exactly: the law explains everything there is to explain.
  fit.r_squared = tss > 0.0 ? 1.0 - rss / tss : 1.0;
  fit.aic = least_squares_aic(rss, n, 2);

  const auto [x_lo, x_hi] = std::minmax_element(x.begin(), x.end());
  const auto [y_lo, y_hi] = std::minmax_element(y.begin(), y.end());
  fit.x_min = *x_lo;
  fit.x_max = *x_hi;
  fit.y_min = *y_lo;
  fit.y_max = *y_hi;
  return fit;
}

}  // namespace crevasse::analysis
