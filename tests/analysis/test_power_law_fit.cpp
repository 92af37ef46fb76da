// Power-law fit y = a·x^b on synthetic data with a known law and log-normal noise.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "analysis/power_law_fit.hpp"

namespace crevasse::analysis {
namespace {

struct Synthetic {
  std::vector<double> x, y;
};

// x log-uniform on [x_lo, x_hi], y = a·x^b·exp(ε), ε ~ N(0, σ²).
Synthetic make_power_law(double a, double b, double sigma, int n, std::mt19937_64& rng,
                         double x_lo = 0.01, double x_hi = 1.0) {
  std::uniform_real_distribution<double> log_x(std::log(x_lo), std::log(x_hi));
  std::normal_distribution<double> noise(0.0, sigma);
  Synthetic s;
  for (int i = 0; i < n; ++i) {
    const double x = std::exp(log_x(rng));
    s.x.push_back(x);
    s.y.push_back(a * std::pow(x, b) * std::exp(noise(rng)));
  }
  return s;
}

// The message must tell the user what is wrong: check the exception and a key phrase.
template <class F>
void expect_invalid_argument(F&& f, const std::string& phrase) {
  try {
    f();
    ADD_FAILURE() << "expected std::invalid_argument mentioning '" << phrase << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << e.what();
  }
}

TEST(FitPowerLaw, ExactDataGiveExactParameters) {
  const std::vector<double> x{0.1, 0.2, 0.5, 1.0, 3.0};
  std::vector<double> y;
  for (double xi : x) y.push_back(2.0 * std::pow(xi, -1.5));
  const PowerLawFit fit = fit_power_law(x, y);
  // Noise-free data: only round-off separates the estimates from the truth.
  EXPECT_NEAR(fit.a(), 2.0, 1e-12);
  EXPECT_NEAR(fit.b(), -1.5, 1e-12);
  EXPECT_NEAR(fit.r_squared, 1.0, 1e-12);
  EXPECT_EQ(fit.n, 5u);
  EXPECT_NEAR(fit.law.value(0.7), 2.0 * std::pow(0.7, -1.5), 1e-10);
}

TEST(FitPowerLaw, RecoversKnownLawWithinIntervals) {
  std::mt19937_64 rng(12345);
  const Synthetic s = make_power_law(0.8, 0.5, 0.1, 30, rng);
  const PowerLawFit fit = fit_power_law(s.x, s.y);
  EXPECT_TRUE(fit.ci_a.contains(0.8)) << fit.ci_a.lower << " " << fit.ci_a.upper;
  EXPECT_TRUE(fit.ci_b.contains(0.5)) << fit.ci_b.lower << " " << fit.ci_b.upper;
  EXPECT_TRUE(fit.ci_b.contains(fit.b()));
  // σ = 0.1 over two decades of x: the law explains almost all the log variance (≈ 0.93 expected).
  EXPECT_GT(fit.r_squared, 0.85);
  // s² estimates σ² = 0.01 with 28 dof; a factor of two either way is far outside its spread.
  EXPECT_GT(fit.residual_variance, 0.005);
  EXPECT_LT(fit.residual_variance, 0.02);
  EXPECT_EQ(fit.n, 30u);
  const ConfidenceInterval band = fit.law.confidence_band(0.1);
  EXPECT_TRUE(band.contains(fit.law.value(0.1)));
  const ConfidenceInterval prediction = fit.law.prediction_band(0.1);
  EXPECT_LT(prediction.lower, band.lower);
  EXPECT_GT(prediction.upper, band.upper);
  // The band is narrowest near the centre of the data (x ≈ 0.1 in log space).
  const auto width = [&](double x) {
    const ConfidenceInterval b = fit.law.confidence_band(x);
    return std::log(b.upper / b.lower);
  };
  EXPECT_LT(width(0.1), width(0.01));
  EXPECT_LT(width(0.1), width(10.0));
  EXPECT_NEAR(fit.aic, least_squares_aic(fit.rss, 30, 2), 1e-12);
}

TEST(FitPowerLaw, IntervalCoverageIsNominal) {
  // 400 data sets of 12 points: the coverage estimate has a standard error of
  // sqrt(0.95·0.05/400) ≈ 0.011, so [0.90, 0.99] is about ±4 standard errors around 0.95.
  std::mt19937_64 rng(2024);
  const int trials = 400;
  int b_covered = 0, a_covered = 0, band_covered = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const Synthetic s = make_power_law(1.7, -0.8, 0.25, 12, rng);
    const PowerLawFit fit = fit_power_law(s.x, s.y);
    b_covered += fit.ci_b.contains(-0.8);
    a_covered += fit.ci_a.contains(1.7);
    band_covered += fit.law.confidence_band(0.3).contains(1.7 * std::pow(0.3, -0.8));
  }
  const auto rate = [&](int covered) { return static_cast<double>(covered) / trials; };
  EXPECT_GE(rate(b_covered), 0.90);
  EXPECT_LE(rate(b_covered), 0.99);
  EXPECT_GE(rate(a_covered), 0.90);
  EXPECT_LE(rate(a_covered), 0.99);
  EXPECT_GE(rate(band_covered), 0.90);
  EXPECT_LE(rate(band_covered), 0.99);
}

TEST(FitPowerLaw, DegenerateInputsAreRejectedClearly) {
  const std::vector<double> empty;
  expect_invalid_argument([&] { fit_power_law(empty, empty); }, "got 0 point(s)");
  const std::vector<double> one{1.0};
  expect_invalid_argument([&] { fit_power_law(one, one); }, "at least 3");
  const std::vector<double> two{1.0, 2.0};
  expect_invalid_argument([&] { fit_power_law(two, two); }, "at least 3");
  const std::vector<double> same_x{0.5, 0.5, 0.5, 0.5};
  const std::vector<double> some_y{1.0, 2.0, 3.0, 4.0};
  expect_invalid_argument([&] { fit_power_law(same_x, some_y); }, "same x");
  const std::vector<double> x{0.1, 0.2, 0.3, 0.4};
  const std::vector<double> nan_y{1.0, 2.0, std::numeric_limits<double>::quiet_NaN(), 4.0};
  expect_invalid_argument([&] { fit_power_law(x, nan_y); }, "row 2");
  const std::vector<double> inf_x{0.1, std::numeric_limits<double>::infinity(), 0.3, 0.4};
  expect_invalid_argument([&] { fit_power_law(inf_x, some_y); }, "not finite");
  const std::vector<double> negative_y{1.0, -2.0, 3.0, 4.0};
  expect_invalid_argument([&] { fit_power_law(x, negative_y); }, "y ≤ 0");
  const std::vector<double> zero_x{0.0, 0.2, 0.3, 0.4};
  expect_invalid_argument([&] { fit_power_law(zero_x, some_y); }, "x ≤ 0");
  expect_invalid_argument([&] { fit_power_law(x, two); }, "give one y per x");
  expect_invalid_argument([&] { fit_power_law(x, some_y, 1.5); }, "confidence level");
}

}  // namespace
}  // namespace crevasse::analysis
