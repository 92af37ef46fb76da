#pragma once
// Power law y = a·x^b fitted by ordinary least squares in log space. The model and
// the interval formulas are written out in docs/fits.md.
#include <array>
#include <cstddef>
#include <span>
#include <vector>

namespace crevasse::analysis {

// A two-sided interval [lower, upper] at the confidence level it was computed for.
struct ConfidenceInterval {
  double lower = 0.0;
  double upper = 0.0;
  bool contains(double value) const { return lower <= value && value <= upper; }
};

// The rows that survive validation, in natural-log space: u = ln x, v = ln y.
struct LogLogData {
  std::vector<double> log_x;
  std::vector<double> log_y;
};

// Checks every row and takes logarithms. Throws std::invalid_argument naming the first bad row
// (NaN/Inf, x ≤ 0 or y ≤ 0), or when x and y differ in length. `what` names the data set in
// the message (e.g. "spacing fit").
LogLogData to_log_log(std::span<const double> x, std::span<const double> y, const char* what);

// A power law ln y = ln a + b·ln x with the joint sampling distribution of (ln a, b): what a
// fit produces and what calibration consumes. Segments of a broken-line fit are expressed in
// the same form, so both kinds of fit feed calibration alike.
struct PowerLaw {
  double log_a = 0.0;  // ln a
  double b = 0.0;      // exponent
  // Covariance of (ln a, b): {var(ln a), cov(ln a, b), var(b)}.
  std::array<double, 3> covariance{0.0, 0.0, 0.0};
  double residual_variance = 0.0;  // s² of the log-space residuals
  double dof = 0.0;                // residual degrees of freedom (n − parameters)

  double a() const;
  double value(double x) const;  // a·x^b
  // Standard error of the fitted ln y at x (the mean curve, not a new observation).
  double log_value_standard_error(double x) const;
  // Confidence band of the fitted curve at x: exp(ln ŷ ± t·se). It bounds the median curve,
  // which in log space is the mean curve.
  ConfidenceInterval confidence_band(double x, double level = 0.95) const;
  // Prediction band for one new observation at x (adds the residual scatter s²).
  ConfidenceInterval prediction_band(double x, double level = 0.95) const;
};

struct PowerLawFit {
  PowerLaw law;
  double level = 0.95;      // confidence level of the intervals below
  double se_log_a = 0.0;    // standard error of ln a
  double se_b = 0.0;        // standard error of b
  ConfidenceInterval ci_a;  // exp of the interval of ln a
  ConfidenceInterval ci_b;
  double r_squared = 0.0;  // in log space
  std::size_t n = 0;
  double rss = 0.0;                 // residual sum of squares in log space
  double residual_variance = 0.0;   // rss/(n − 2)
  double aic = 0.0;                 // n·ln(rss/n) + 2k with k = 3 (ln a, b, σ²)
  double x_min = 0.0, x_max = 0.0;  // range of the data the law was fitted to
  double y_min = 0.0, y_max = 0.0;

  double a() const { return law.a(); }
  double b() const { return law.b; }
};

// Two-sided Student-t quantile t_{(1+level)/2, dof}. Throws for dof ≤ 0 or level ∉ (0, 1).
double student_t_quantile(double level, double dof);

// Fits y = a·x^b. Throws std::invalid_argument for bad rows (see to_log_log), fewer than 3
// points, all x equal, or level ∉ (0, 1).
PowerLawFit fit_power_law(std::span<const double> x, std::span<const double> y,
                          double level = 0.95);

// Gaussian-likelihood AIC of a least-squares fit: n·ln(rss/n) + 2·(parameters + 1), the +1
// being σ² (Akaike 1974; Burnham & Anderson 2002). A perfect fit (rss = 0) is clamped to a tiny
// rss.
double least_squares_aic(double rss, std::size_t n, std::size_t parameters);

}  // namespace crevasse::analysis
