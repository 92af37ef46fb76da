#include "analysis/broken_line_fit.hpp"

#include <gsl/gsl_cdf.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace crevasse::analysis {
namespace {

// Parameter order in the covariance matrix: α (ln y at the breakpoint), b1, b2, u*.
constexpr int kAlpha = 0, kB1 = 1, kB2 = 2, kBreak = 3;

struct LinearSolution {
  double alpha = 0.0;
  double b1 = 0.0;
  double b2 = 0.0;
  double rss = 0.0;
};

// For a fixed breakpoint the model is linear in (α, b1, b2): profiling u* reduces the
// nonlinear problem to a one-dimensional search over small linear least-squares problems.
class ProfileProblem {
 public:
  ProfileProblem(const LogLogData& data, const BrokenLineOptions& options)
      : u_(data.log_x), v_(data.log_y), fixed_b1_(options.fixed_b1), fixed_b2_(options.fixed_b2) {}

  int free_linear_parameters() const { return 1 + !fixed_b1_ + !fixed_b2_; }

  LinearSolution solve(double u_star) const {
    const int n = static_cast<int>(u_.size());
    Eigen::MatrixXd design(n, free_linear_parameters());
    Eigen::VectorXd target(n);
    for (int i = 0; i < n; ++i) {
      const double below = std::min(u_[i] - u_star, 0.0);
      const double above = std::max(u_[i] - u_star, 0.0);
      int column = 0;
      design(i, column++) = 1.0;
      target(i) = v_[i];
      if (fixed_b1_)
        target(i) -= *fixed_b1_ * below;
      else
        design(i, column++) = below;
      if (fixed_b2_)
        target(i) -= *fixed_b2_ * above;
      else
        design(i, column++) = above;
    }
    const Eigen::VectorXd beta = design.colPivHouseholderQr().solve(target);
    LinearSolution solution;
    int column = 0;
    solution.alpha = beta(column++);
    solution.b1 = fixed_b1_ ? *fixed_b1_ : beta(column++);
    solution.b2 = fixed_b2_ ? *fixed_b2_ : beta(column++);
    solution.rss = (target - design * beta).squaredNorm();
    return solution;
  }

  double rss(double u_star) const { return solve(u_star).rss; }

 private:
  const std::vector<double>& u_;
  const std::vector<double>& v_;
  std::optional<double> fixed_b1_, fixed_b2_;
};

// Golden-section minimisation of a continuous function on [lo, hi]. The profile RSS is smooth
// between data abscissae but has kinks at them, so a derivative-free bracketing search is used.
template <class F>
double golden_section_minimum(F&& f, double lo, double hi) {
  const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
  double x1 = hi - ratio * (hi - lo), x2 = lo + ratio * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  for (int iteration = 0; iteration < 80 && hi - lo > 1e-12 * (1.0 + std::abs(lo)); ++iteration) {
    if (f1 <= f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - ratio * (hi - lo);
      f1 = f(x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + ratio * (hi - lo);
      f2 = f(x2);
    }
  }
  return f1 <= f2 ? x1 : x2;
}

// Bisection for the point between `inside` (RSS ≤ threshold) and `outside` where the profile
// RSS crosses the threshold.
template <class F>
double threshold_crossing(F&& rss, double inside, double outside, double threshold) {
  for (int iteration = 0; iteration < 60; ++iteration) {
    const double middle = 0.5 * (inside + outside);
    (rss(middle) <= threshold ? inside : outside) = middle;
  }
  return 0.5 * (inside + outside);
}

// gᵀ C h for the 4×4 row-major covariance. Infinite entries belong to an unidentified u*
// (equal slopes), whose shift is absorbed by α: leaving them out gives the result conditional
// on u*, which is what the curve and the segment laws then depend on.
double covariance_form(const std::array<double, 4>& g, const std::array<double, 16>& covariance,
                       const std::array<double, 4>& h) {
  double sum = 0.0;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      const double c = covariance[4 * i + j];
      if (std::isfinite(c) && g[i] != 0.0 && h[j] != 0.0) sum += g[i] * c * h[j];
    }
  }
  return sum;
}

}  // namespace

double BrokenLineFit::value(double x) const {
  const double u = std::log(x), u_star = std::log(breakpoint);
  const double slope = u < u_star ? b[0] : b[1];
  return y_at_breakpoint * std::exp(slope * (u - u_star));
}

ConfidenceInterval BrokenLineFit::confidence_band(double x) const {
  const double u = std::log(x), u_star = std::log(breakpoint);
  // Gradient of ln ŷ(u) with respect to (α, b1, b2, u*).
  const std::array<double, 4> gradient{1.0, std::min(u - u_star, 0.0), std::max(u - u_star, 0.0),
                                       u < u_star ? -b[0] : -b[1]};
  const double variance = covariance_form(gradient, covariance, gradient);
  const double half = student_t_quantile(level, dof) * std::sqrt(std::max(variance, 0.0));
  const double centre = std::log(value(x));
  return {std::exp(centre - half), std::exp(centre + half)};
}

BrokenLineFit fit_broken_line(std::span<const double> x, std::span<const double> y,
                              const BrokenLineOptions& options) {
  const LogLogData data = to_log_log(x, y, "broken-line fit");
  const std::size_t n = data.log_x.size();
  const std::size_t per_side = std::max<std::size_t>(options.min_points_per_side, 1);
  if (n < 2 * per_side) {
    throw std::invalid_argument("broken-line fit: got " + std::to_string(n) +
                                " point(s); at least " + std::to_string(2 * per_side) +
                                " are needed (" + std::to_string(per_side) +
                                " on each side of the breakpoint)");
  }
  if (options.grid_points < 3) {
    throw std::invalid_argument("broken-line fit: grid_points must be at least 3, got " +
                                std::to_string(options.grid_points));
  }
  ProfileProblem problem(data, options);
  BrokenLineFit fit;
  fit.level = options.level;
  fit.n = n;
  fit.parameters = static_cast<std::size_t>(problem.free_linear_parameters()) + 1;  // + u*
  if (n <= fit.parameters) {
    throw std::invalid_argument("broken-line fit: " + std::to_string(n) +
                                " points leave no residual "
                                "degree of freedom for " +
                                std::to_string(fit.parameters) +
                                " parameters; add points or fix an exponent");
  }
  fit.dof = static_cast<double>(n - fit.parameters);
  const double t = student_t_quantile(options.level, fit.dof);  // also validates the level

  // Admissible breakpoints: at least `per_side` points, and two distinct x so that the
  // segment's own data carry its exponent, both below (u < u*) and above (u ≥ u*).
  std::vector<double> sorted_u = data.log_x;
  std::sort(sorted_u.begin(), sorted_u.end());
  std::vector<double> distinct_u = sorted_u;
  distinct_u.erase(std::unique(distinct_u.begin(), distinct_u.end()), distinct_u.end());
  const bool enough_distinct = distinct_u.size() >= 4;
  const double u_lo = enough_distinct ? std::max(sorted_u[per_side - 1], distinct_u[1]) : 0.0;
  const double u_hi =
      enough_distinct ? std::min(sorted_u[n - per_side], distinct_u[distinct_u.size() - 2]) : 0.0;
  if (!enough_distinct || !(u_lo < u_hi)) {
    throw std::invalid_argument("broken-line fit: the data have too few distinct x values to put " +
                                std::to_string(per_side) +
                                " points (and 2 distinct x) on each "
                                "side of a breakpoint; "
                                "spread the study over more x (Π) values");
  }
  fit.admissible_breakpoint_min = std::exp(u_lo);
  fit.admissible_breakpoint_max = std::exp(u_hi);

  // Grid over (u_lo, u_hi]: u_lo itself would leave one side a point short.
  const std::size_t grid_size = options.grid_points;
  std::vector<double> grid(grid_size), grid_rss(grid_size);
  for (std::size_t j = 0; j < grid_size; ++j) {
    grid[j] = u_lo + (u_hi - u_lo) * static_cast<double>(j + 1) / static_cast<double>(grid_size);
    grid_rss[j] = problem.rss(grid[j]);
  }
  const std::size_t best = static_cast<std::size_t>(
      std::min_element(grid_rss.begin(), grid_rss.end()) - grid_rss.begin());
  const double bracket_lo = best == 0 ? u_lo + 1e-9 * (u_hi - u_lo) : grid[best - 1];
  const double bracket_hi = best + 1 == grid_size ? u_hi : grid[best + 1];
  const auto profile_rss = [&](double u_star) { return problem.rss(u_star); };
  double u_star = golden_section_minimum(profile_rss, bracket_lo, bracket_hi);
  if (problem.rss(u_star) > grid_rss[best]) u_star = grid[best];

  const LinearSolution solution = problem.solve(u_star);
  fit.rss = solution.rss;
  fit.residual_variance = solution.rss / fit.dof;
  fit.aic = least_squares_aic(solution.rss, n, fit.parameters);
  fit.breakpoint = std::exp(u_star);
  fit.y_at_breakpoint = std::exp(solution.alpha);
  fit.b = {solution.b1, solution.b2};
  fit.b_fixed = {options.fixed_b1.has_value(), options.fixed_b2.has_value()};

  // Profile-likelihood interval for u*: all u* whose profile RSS stays below
  // RSS_min·(1 + F_{1,n−p}(level)/(n−p)) (Bates & Watts 1988, ch. 6; Hinkley 1969).
  // The hull over the grid is taken, so a profile with several dips gives a wider interval.
  const double threshold =
      solution.rss * (1.0 + gsl_cdf_fdist_Pinv(options.level, 1.0, fit.dof) / fit.dof);
  std::size_t first_inside = grid_size, last_inside = 0;
  for (std::size_t j = 0; j < grid_size; ++j) {
    if (grid_rss[j] <= threshold) {
      first_inside = std::min(first_inside, j);
      last_inside = j;
    }
  }
  double ci_lo = u_star, ci_hi = u_star;
  if (first_inside == grid_size) {
    // A dip narrower than the grid: only the refined minimum is inside.
    ci_lo = threshold_crossing(profile_rss, u_star, bracket_lo, threshold);
    ci_hi = threshold_crossing(profile_rss, u_star, bracket_hi, threshold);
  } else {
    // Below grid[0] lies the open end (u_lo, grid[0]]; u_lo is the edge of what can be fitted.
    if (first_inside > 0) {
      ci_lo =
          threshold_crossing(profile_rss, grid[first_inside], grid[first_inside - 1], threshold);
    } else if (problem.rss(u_lo) <= threshold) {
      fit.breakpoint_ci_clipped_low = true;
      ci_lo = u_lo;
    } else {
      ci_lo = threshold_crossing(profile_rss, grid[0], u_lo, threshold);
    }
    if (last_inside + 1 < grid_size) {
      ci_hi = threshold_crossing(profile_rss, grid[last_inside], grid[last_inside + 1], threshold);
    } else {
      fit.breakpoint_ci_clipped_high = true;
      ci_hi = u_hi;
    }
  }
  fit.breakpoint_ci = {std::exp(std::min(ci_lo, u_star)), std::exp(std::max(ci_hi, u_star))};

  // Linearised covariance of the free parameters, s²(JᵀJ)⁻¹, with J the Jacobian of the
  // model in (α, b1, b2, u*) (Seber & Wild 2003, ch. 9; Muggeo 2003).
  std::vector<int> free_index{kAlpha};
  if (!fit.b_fixed[0]) free_index.push_back(kB1);
  if (!fit.b_fixed[1]) free_index.push_back(kB2);
  free_index.push_back(kBreak);
  const int k = static_cast<int>(free_index.size());
  Eigen::MatrixXd jacobian(static_cast<int>(n), k);
  for (std::size_t i = 0; i < n; ++i) {
    const double du = data.log_x[i] - u_star;
    const std::array<double, 4> row{1.0, std::min(du, 0.0), std::max(du, 0.0),
                                    du < 0.0 ? -fit.b[0] : -fit.b[1]};
    for (int c = 0; c < k; ++c) jacobian(static_cast<int>(i), c) = row[free_index[c]];
  }
  const Eigen::MatrixXd information = jacobian.transpose() * jacobian;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(information);
  // Equal slopes make u* unidentifiable (its column is a multiple of the intercept's): its
  // variance is infinite, and the other parameters are reported conditional on u*.
  Eigen::MatrixXd free_covariance = Eigen::MatrixXd::Zero(k, k);
  if (lu.isInvertible()) {
    free_covariance = fit.residual_variance * lu.inverse();
  } else {
    // The linear block is invertible: admissibility puts two distinct x on each side.
    const Eigen::MatrixXd conditional = information.topLeftCorner(k - 1, k - 1);
    free_covariance.topLeftCorner(k - 1, k - 1) =
        fit.residual_variance * conditional.fullPivLu().inverse();
    free_covariance(k - 1, k - 1) = std::numeric_limits<double>::infinity();
  }
  for (int r = 0; r < k; ++r)
    for (int c = 0; c < k; ++c)
      fit.covariance[4 * free_index[r] + free_index[c]] = free_covariance(r, c);
  const auto cov = [&](int i, int j) { return fit.covariance[4 * i + j]; };

  const double se_alpha = std::sqrt(cov(kAlpha, kAlpha));
  fit.y_at_breakpoint_ci = {std::exp(solution.alpha - t * se_alpha),
                            std::exp(solution.alpha + t * se_alpha)};
  for (int s = 0; s < 2; ++s) {
    const int slope_index = s == 0 ? kB1 : kB2;
    fit.se_b[s] = std::sqrt(cov(slope_index, slope_index));
    fit.ci_b[s] = {fit.b[s] - t * fit.se_b[s], fit.b[s] + t * fit.se_b[s]};
    // ln a_s = α − b_s·u*: propagate (α, b_s, u*) to (ln a_s, b_s) with G = ∂(ln a_s, b_s)/∂θ.
    std::array<double, 4> grad_log_a{0.0, 0.0, 0.0, 0.0};
    grad_log_a[kAlpha] = 1.0;
    grad_log_a[slope_index] = -u_star;
    grad_log_a[kBreak] = -fit.b[s];
    std::array<double, 4> grad_b{0.0, 0.0, 0.0, 0.0};
    grad_b[slope_index] = 1.0;
    const double var_log_a = covariance_form(grad_log_a, fit.covariance, grad_log_a);
    const double cov_log_a_b = covariance_form(grad_log_a, fit.covariance, grad_b);
    PowerLaw& law = fit.segments[s];
    law.log_a = solution.alpha - fit.b[s] * u_star;
    law.b = fit.b[s];
    law.covariance = {var_log_a, cov_log_a_b, cov(slope_index, slope_index)};
    law.residual_variance = fit.residual_variance;
    law.dof = fit.dof;
    const double se_log_a = std::sqrt(std::max(var_log_a, 0.0));
    fit.ci_a[s] = {std::exp(law.log_a - t * se_log_a), std::exp(law.log_a + t * se_log_a)};
  }

  fit.segment_x_min = {std::numeric_limits<double>::infinity(),
                       std::numeric_limits<double>::infinity()};
  fit.segment_x_max = {-std::numeric_limits<double>::infinity(),
                       -std::numeric_limits<double>::infinity()};
  fit.segment_y_min = fit.segment_x_min;
  fit.segment_y_max = fit.segment_x_max;
  for (std::size_t i = 0; i < n; ++i) {
    const int s = data.log_x[i] < u_star ? 0 : 1;
    ++fit.segment_n[s];
    fit.segment_x_min[s] = std::min(fit.segment_x_min[s], x[i]);
    fit.segment_x_max[s] = std::max(fit.segment_x_max[s], x[i]);
    fit.segment_y_min[s] = std::min(fit.segment_y_min[s], y[i]);
    fit.segment_y_max[s] = std::max(fit.segment_y_max[s], y[i]);
  }

  // Model comparison with one power law on the same rows (extra sum of squares F test;
  // Draper & Smith 1998; AIC: Burnham & Anderson 2002).
  fit.single = fit_power_law(x, y, options.level);
  ModelComparison& comparison = fit.comparison;
  comparison.rss_single = fit.single.rss;
  comparison.rss_broken = fit.rss;
  comparison.aic_single = fit.single.aic;
  comparison.aic_broken = fit.aic;
  comparison.df_numerator = static_cast<double>(fit.parameters) - 2.0;
  comparison.df_denominator = fit.dof;
  const bool aic_prefers_broken = comparison.aic_broken < comparison.aic_single;
  if (comparison.df_numerator > 0.0) {
    const double reduction = std::max(comparison.rss_single - comparison.rss_broken, 0.0);
    const double rss_broken = std::max(comparison.rss_broken, std::numeric_limits<double>::min());
    comparison.f_statistic =
        (reduction / comparison.df_numerator) / (rss_broken / comparison.df_denominator);
    // An exact broken-line fit overflows F; GSL's default handler would abort on infinity.
    comparison.p_value = std::isfinite(comparison.f_statistic)
                             ? gsl_cdf_fdist_Q(comparison.f_statistic, comparison.df_numerator,
                                               comparison.df_denominator)
                             : 0.0;
    comparison.two_regimes_warranted = comparison.p_value < 0.05 && aic_prefers_broken;
  } else {
    comparison.f_statistic = std::numeric_limits<double>::quiet_NaN();
    comparison.p_value = std::numeric_limits<double>::quiet_NaN();
    comparison.two_regimes_warranted = aic_prefers_broken;
  }
  return fit;
}

}  // namespace crevasse::analysis
