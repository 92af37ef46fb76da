// Broken-line (two-regime) fit on synthetic data with a known breakpoint.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "analysis/broken_line_fit.hpp"

namespace crevasse::analysis {
namespace {

struct TwoRegimeLaw {
  double breakpoint = 0.1;  // x*
  double y_star = 2.0;      // y at x*
  double b1 = 1.0;
  double b2 = 0.2;
  double operator()(double x) const {
    return y_star * std::pow(x / breakpoint, x < breakpoint ? b1 : b2);
  }
};

// n points log-uniform on [1e-3, 1] with log-normal noise of standard deviation σ.
template <class Law>
void make_data(const Law& law, double sigma, int n, std::mt19937_64& rng, std::vector<double>& x,
               std::vector<double>& y) {
  std::uniform_real_distribution<double> log_x(std::log(1e-3), 0.0);
  std::normal_distribution<double> noise(0.0, sigma);
  x.clear();
  y.clear();
  for (int i = 0; i < n; ++i) {
    x.push_back(std::exp(log_x(rng)));
    y.push_back(law(x.back()) * std::exp(noise(rng)));
  }
}

TEST(FitBrokenLine, NoiseFreeDataGiveTheExactBreakpoint) {
  const TwoRegimeLaw law;
  std::vector<double> x, y;
  for (int i = 0; i < 25; ++i) {
    x.push_back(std::pow(10.0, -3.0 + 3.0 * i / 24.0));
    y.push_back(law(x.back()));
  }
  const BrokenLineFit fit = fit_broken_line(x, y);
  // Exact data: the golden-section refinement converges to round-off, far below 1e-6.
  EXPECT_NEAR(fit.breakpoint / law.breakpoint, 1.0, 1e-6);
  EXPECT_NEAR(fit.b[0], law.b1, 1e-6);
  EXPECT_NEAR(fit.b[1], law.b2, 1e-6);
  EXPECT_NEAR(fit.y_at_breakpoint, law.y_star, 1e-6);
  EXPECT_NEAR(fit.value(0.01), law(0.01), 1e-6);
  EXPECT_TRUE(fit.comparison.two_regimes_warranted);
}

TEST(FitBrokenLine, RecoversBreakpointWithinItsInterval) {
  const TwoRegimeLaw law;
  std::mt19937_64 rng(7);
  std::vector<double> x, y;
  make_data(law, 0.1, 40, rng, x, y);
  const BrokenLineFit fit = fit_broken_line(x, y);
  EXPECT_TRUE(fit.breakpoint_ci.contains(law.breakpoint))
      << fit.breakpoint_ci.lower << " " << fit.breakpoint << " " << fit.breakpoint_ci.upper;
  EXPECT_TRUE(fit.breakpoint_ci.contains(fit.breakpoint));
  EXPECT_FALSE(fit.breakpoint_ci_clipped_low);
  EXPECT_FALSE(fit.breakpoint_ci_clipped_high);
  EXPECT_TRUE(fit.ci_b[0].contains(law.b1)) << fit.ci_b[0].lower << " " << fit.ci_b[0].upper;
  EXPECT_TRUE(fit.ci_b[1].contains(law.b2)) << fit.ci_b[1].lower << " " << fit.ci_b[1].upper;
  EXPECT_TRUE(fit.y_at_breakpoint_ci.contains(law.y_star));
  // Segment laws in y = a·x^b form: a_i = y*·x*^(−b_i).
  for (int s = 0; s < 2; ++s) {
    const double true_a = law.y_star * std::pow(law.breakpoint, -(s == 0 ? law.b1 : law.b2));
    EXPECT_TRUE(fit.ci_a[s].contains(true_a))
        << s << ": " << fit.ci_a[s].lower << " " << true_a << " " << fit.ci_a[s].upper;
    EXPECT_GE(fit.segment_n[s], 3u);
  }
  EXPECT_EQ(fit.segment_n[0] + fit.segment_n[1], 40u);
  EXPECT_TRUE(fit.confidence_band(0.03).contains(fit.value(0.03)));
  EXPECT_TRUE(fit.comparison.two_regimes_warranted);
  EXPECT_LT(fit.comparison.p_value, 0.05);
  EXPECT_LT(fit.comparison.aic_broken, fit.comparison.aic_single);
}

TEST(FitBrokenLine, ModelComparisonPicksTheRightNumberOfRegimes) {
  // 50 data sets of each kind. The nominal F p-value ignores the breakpoint search (Davies
  // 1987), so false detections run above 5 %; 20 % allows for that and for sampling spread.
  // With a contrast of 0.8 in exponent and σ = 0.1, a missed detection should be very rare;
  // 90 % leaves room for a few unlucky draws.
  std::mt19937_64 rng(99);
  std::vector<double> x, y;
  int detected_in_two = 0, detected_in_one = 0;
  const int trials = 50;
  for (int trial = 0; trial < trials; ++trial) {
    make_data(TwoRegimeLaw{}, 0.1, 30, rng, x, y);
    detected_in_two += fit_broken_line(x, y).comparison.two_regimes_warranted;
    make_data([](double xi) { return 3.0 * std::pow(xi, 0.6); }, 0.1, 30, rng, x, y);
    detected_in_one += fit_broken_line(x, y).comparison.two_regimes_warranted;
  }
  EXPECT_GE(detected_in_two, trials * 9 / 10);
  EXPECT_LE(detected_in_one, trials / 5);
}

TEST(FitBrokenLine, BreakpointIntervalCoverage) {
  // 150 data sets; the profile interval is asymptotic, so allow [0.85, 1.0]: the binomial
  // standard error at 0.95 is ≈ 0.018 and small samples make such intervals a little liberal.
  std::mt19937_64 rng(31);
  std::vector<double> x, y;
  const TwoRegimeLaw law;
  int covered = 0;
  const int trials = 150;
  for (int trial = 0; trial < trials; ++trial) {
    make_data(law, 0.15, 30, rng, x, y);
    covered += fit_broken_line(x, y).breakpoint_ci.contains(law.breakpoint);
  }
  const double rate = static_cast<double>(covered) / trials;
  EXPECT_GE(rate, 0.85);
  EXPECT_LE(rate, 1.0);
}

TEST(FitBrokenLine, FixedExponentsAreHonoured) {
  const TwoRegimeLaw law;
  std::mt19937_64 rng(5);
  std::vector<double> x, y;
  make_data(law, 0.05, 30, rng, x, y);
  BrokenLineOptions options;
  options.fixed_b1 = 1.0;
  const BrokenLineFit fit = fit_broken_line(x, y, options);
  EXPECT_EQ(fit.b[0], 1.0);
  EXPECT_TRUE(fit.b_fixed[0]);
  EXPECT_EQ(fit.se_b[0], 0.0);
  EXPECT_EQ(fit.ci_b[0].lower, 1.0);
  EXPECT_EQ(fit.ci_b[0].upper, 1.0);
  EXPECT_EQ(fit.parameters, 3u);
  EXPECT_TRUE(fit.breakpoint_ci.contains(law.breakpoint));
  EXPECT_TRUE(fit.ci_b[1].contains(law.b2));
  EXPECT_EQ(fit.comparison.df_numerator, 1.0);

  options.fixed_b2 = 0.2;
  const BrokenLineFit both = fit_broken_line(x, y, options);
  EXPECT_EQ(both.b[1], 0.2);
  // Nothing to test with F when the broken line has no extra parameter: AIC decides alone.
  EXPECT_TRUE(std::isnan(both.comparison.p_value));
  EXPECT_TRUE(both.comparison.two_regimes_warranted);
}

TEST(FitBrokenLine, ExactSingleLawLeavesTheBreakpointFreeButTheCurveExact) {
  // y = 2x exactly: both slopes are 1, so u* is not identifiable (any u* fits) while the curve
  // itself is exact; the band must stay finite and collapse onto it, and one regime suffices.
  const std::vector<double> x{1, 2, 3, 4, 5, 6, 7, 8};
  std::vector<double> y;
  for (double xi : x) y.push_back(2.0 * xi);
  const BrokenLineFit fit = fit_broken_line(x, y);
  EXPECT_NEAR(fit.b[0], 1.0, 1e-9);  // exact data: round-off only
  EXPECT_NEAR(fit.b[1], 1.0, 1e-9);
  EXPECT_FALSE(fit.comparison.two_regimes_warranted);
  const ConfidenceInterval band = fit.confidence_band(3.0);
  EXPECT_NEAR(band.lower, 6.0, 1e-6);
  EXPECT_NEAR(band.upper, 6.0, 1e-6);
}

TEST(FitBrokenLine, DegenerateInputsAreRejectedClearly) {
  const auto expect_message = [](const std::vector<double>& x, const std::vector<double>& y,
                                 const std::string& phrase) {
    try {
      fit_broken_line(x, y);
      ADD_FAILURE() << "expected std::invalid_argument mentioning '" << phrase << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << e.what();
    }
  };
  expect_message({}, {}, "at least 6");
  expect_message({1.0}, {1.0}, "at least 6");
  expect_message({1, 1, 1, 1, 1, 1, 1}, {1, 2, 3, 4, 5, 6, 7}, "too few distinct x");
  expect_message({1, 2, 3, 4, 5, 6, 7}, {1, 2, std::nan(""), 4, 5, 6, 7}, "row 2");
  expect_message({1, 2, 3, 4, 5, 6, 7}, {1, 2, 3, 4, 5, 6, -7}, "row 6");
}

}  // namespace
}  // namespace crevasse::analysis
