#pragma once
// Continuous two-segment ("broken-line") fit in log-log space, for a law that changes exponent
// between two regimes, and its comparison with a single power law. Equations,
// the breakpoint interval and the comparison rule are in docs/fits.md.
#include <array>
#include <cstddef>
#include <optional>
#include <span>

#include "analysis/power_law_fit.hpp"

namespace crevasse::analysis {

struct BrokenLineOptions {
  // Exponent of each segment: free when empty, held at the given value otherwise (e.g. a
  // regime where theory fixes L ∝ c, b = 1).
  std::optional<double> fixed_b1;  // segment below the breakpoint
  std::optional<double> fixed_b2;  // segment above the breakpoint
  double level = 0.95;
  std::size_t min_points_per_side = 3;
  std::size_t grid_points = 200;  // profile grid over the admissible breakpoints
};

// One power law against the broken line, on the same data.
struct ModelComparison {
  double rss_single = 0.0;
  double rss_broken = 0.0;
  // Extra-sum-of-squares F test (df_numerator = extra parameters of the broken line). NaN when
  // the broken line has no more parameters than the single law (both exponents fixed).
  double f_statistic = 0.0;
  double df_numerator = 0.0;
  double df_denominator = 0.0;
  double p_value = 0.0;
  double aic_single = 0.0;
  double aic_broken = 0.0;
  // p < 0.05 and AIC lower for the broken line (AIC alone when the F test is undefined).
  bool two_regimes_warranted = false;
};

struct BrokenLineFit {
  double level = 0.95;
  std::size_t n = 0;
  std::size_t parameters = 0;  // free parameters: ln y*, u*, and each free exponent
  double dof = 0.0;            // n − parameters
  double rss = 0.0;            // log space
  double residual_variance = 0.0;
  double aic = 0.0;

  // The breakpoint x* = exp(u*) and its profile-likelihood interval. A "clipped" side means the
  // interval reached the edge of the admissible range (≥ min_points_per_side on each side):
  // the data do not bound x* there.
  double breakpoint = 0.0;
  ConfidenceInterval breakpoint_ci;
  bool breakpoint_ci_clipped_low = false;
  bool breakpoint_ci_clipped_high = false;
  double admissible_breakpoint_min = 0.0;  // x* search range (exclusive lower end)
  double admissible_breakpoint_max = 0.0;

  // y* = exp(α), the curve's value at the breakpoint, with its Wald interval.
  double y_at_breakpoint = 0.0;
  ConfidenceInterval y_at_breakpoint_ci;

  std::array<double, 2> b{0.0, 0.0};          // segment exponents (below, above)
  std::array<bool, 2> b_fixed{false, false};  // held by the user
  std::array<double, 2> se_b{0.0, 0.0};       // 0 when fixed
  std::array<ConfidenceInterval, 2> ci_b;     // [b, b] when fixed
  // Each segment as y = a_i·x^b_i with the joint distribution of (ln a_i, b_i), accounting for
  // the uncertainty of the breakpoint; usable for calibration like a single fit.
  std::array<PowerLaw, 2> segments;
  std::array<ConfidenceInterval, 2> ci_a;
  // Data on each side of the breakpoint (x < x* below, x ≥ x* above).
  std::array<std::size_t, 2> segment_n{0, 0};
  std::array<double, 2> segment_x_min{0.0, 0.0}, segment_x_max{0.0, 0.0};
  std::array<double, 2> segment_y_min{0.0, 0.0}, segment_y_max{0.0, 0.0};

  // Covariance of (α, b1, b2, u*) from the linearised model (zero rows for fixed exponents),
  // row-major 4×4.
  std::array<double, 16> covariance{};

  PowerLawFit single;  // the single power law on the same data
  ModelComparison comparison;

  double value(double x) const;
  // Confidence band of the fitted curve (delta method through all free parameters).
  ConfidenceInterval confidence_band(double x) const;
};

// Fits the broken line to (x, y). Throws std::invalid_argument for bad rows (see to_log_log),
// too few points (fewer than 2·min_points_per_side, or no residual degree of freedom), or
// when the admissible breakpoint range is empty (too few distinct x).
BrokenLineFit fit_broken_line(std::span<const double> x, std::span<const double> y,
                              const BrokenLineOptions& options = {});

}  // namespace crevasse::analysis
