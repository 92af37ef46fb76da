// Calibration: forward prediction of spacing/depth and inversion of an observed spacing for the
// tensile strength c, against synthetic studies with a known law.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "analysis/calibration.hpp"

namespace crevasse::analysis {
namespace {

constexpr double kRhoG = 917.0 * 9.81;

// A synthetic study: Π log-uniform on [0.01, 1], L/H = a·Π^b·exp(ε), ε ~ N(0, σ²).
PowerLawFit synthetic_study_fit(double a, double b, double sigma, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> log_pi(std::log(0.01), 0.0);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<double> pi, ratio;
  for (int i = 0; i < n; ++i) {
    pi.push_back(std::exp(log_pi(rng)));
    ratio.push_back(a * std::pow(pi.back(), b) * std::exp(noise(rng)));
  }
  return fit_power_law(pi, ratio);
}

TEST(CalibCohesionRatio, MatchesDefinition) {
  // Π = c/(ρ g H) with the default ρ_i, g; exact arithmetic up to round-off.
  EXPECT_NEAR(cohesion_ratio(1e5, 100.0), 1e5 / (kRhoG * 100.0), 1e-15);
  EXPECT_NEAR(cohesion_ratio(1e5, 100.0, {900.0, 10.0}), 1e5 / 9e5, 1e-15);
}

TEST(CalibRoundTrip, InvertingAPredictedSpacingRecoversCohesion) {
  const double a = 0.9, b = 0.5;
  const RegimeLaw regime = regime_from_fit("strength", synthetic_study_fit(a, b, 0.05, 30, 11));
  const double c = 150e3, h = 200.0;  // Π ≈ 0.083, inside the study
  const CrevassePrediction predicted = predict_crevasses(regime, c, h);
  EXPECT_EQ(predicted.regime, "strength");
  EXPECT_TRUE(predicted.spacing_m.interval.contains(predicted.spacing_m.value));
  const double true_spacing = a * std::pow(cohesion_ratio(c, h), b) * h;
  EXPECT_TRUE(predicted.spacing_m.interval.contains(true_spacing));
  EXPECT_LT(predicted.spacing_prediction_m.lower, predicted.spacing_m.interval.lower);

  // The fitted law's own spacing inverts back to c exactly (same law both ways).
  SpacingObservation observed{predicted.spacing_m.value, std::nullopt, std::nullopt, h};
  const CohesionEstimate estimate = invert_spacing_for_cohesion(regime, observed);
  EXPECT_NEAR(estimate.tensile_strength_pa / c, 1.0, 1e-10);  // round-off only
  EXPECT_TRUE(estimate.interval_pa.contains(c));
  EXPECT_EQ(estimate.regime, "strength");
  ASSERT_TRUE(estimate.pi_in_regime_range.has_value());
  EXPECT_TRUE(*estimate.pi_in_regime_range);
  EXPECT_NEAR(estimate.cohesion_ratio_pi->value, cohesion_ratio(c, h), 1e-12);
  EXPECT_FALSE(estimate.thickness_independent);

  // The spacing the true law gives is also inverted to an interval holding the true c.
  observed.spacing_m = true_spacing;
  EXPECT_TRUE(invert_spacing_for_cohesion(regime, observed).interval_pa.contains(c));

  // Quartiles widen the interval; the same inputs give the same interval (fixed seed).
  SpacingObservation spread = observed;
  spread.spacing_q25_m = 0.8 * true_spacing;
  spread.spacing_q75_m = 1.3 * true_spacing;
  const CohesionEstimate wide = invert_spacing_for_cohesion(regime, spread);
  const CohesionEstimate narrow = invert_spacing_for_cohesion(regime, observed);
  EXPECT_LT(wide.interval_pa.lower, narrow.interval_pa.lower);
  EXPECT_GT(wide.interval_pa.upper, narrow.interval_pa.upper);
  const CohesionEstimate again = invert_spacing_for_cohesion(regime, spread);
  EXPECT_EQ(again.interval_pa.lower, wide.interval_pa.lower);
  EXPECT_EQ(again.interval_pa.upper, wide.interval_pa.upper);
}

TEST(CalibRoundTrip, DepthIsPredictedWithItsLaw) {
  RegimeLaw regime = regime_from_fit("strength", synthetic_study_fit(0.9, 0.5, 0.05, 30, 3),
                                     synthetic_study_fit(0.4, 0.3, 0.05, 30, 4).law);
  const double c = 100e3, h = 300.0;
  const CrevassePrediction predicted = predict_crevasses(regime, c, h);
  ASSERT_TRUE(predicted.depth_m.has_value());
  const double true_depth = 0.4 * std::pow(cohesion_ratio(c, h), 0.3) * h;
  EXPECT_TRUE(predicted.depth_m->interval.contains(true_depth));
  EXPECT_TRUE(predicted.depth_prediction_m->contains(true_depth));
}

TEST(CalibRoundTrip, IntervalCoverageOverSyntheticStudies) {
  // 100 studies, each inverting one site whose spacing scatters about the true law as the
  // cases do. The Monte Carlo interval is approximate (it treats inverse prediction with a
  // normal linearisation of the uncertainty), so allow [0.85, 1.0]; the binomial standard
  // error at 0.95 is ≈ 0.022.
  std::mt19937_64 rng(77);
  std::normal_distribution<double> site_scatter(0.0, 0.1);
  CalibrationOptions options;
  options.monte_carlo_samples = 4000;  // percentiles to ~1 %, enough for a coverage count
  int covered = 0;
  const int trials = 100;
  const double a = 1.2, b = 0.6, c = 80e3, h = 150.0;
  for (int trial = 0; trial < trials; ++trial) {
    const RegimeLaw regime =
        regime_from_fit("strength", synthetic_study_fit(a, b, 0.1, 20, 1000 + trial));
    const double spacing = a * std::pow(cohesion_ratio(c, h), b) * h * std::exp(site_scatter(rng));
    try {
      covered += invert_spacing_for_cohesion(regime, {spacing, {}, {}, h}, options)
                     .interval_pa.contains(c);
    } catch (const std::out_of_range&) {
      // A site beyond this study's L/H range is refused; count it as not covered.
    }
  }
  EXPECT_GE(static_cast<double>(covered) / trials, 0.85);
}

TEST(CalibThickness, MissingThicknessNeedsAnExponentOfOne) {
  const RegimeLaw regime = regime_from_fit("strength", synthetic_study_fit(0.9, 0.5, 0.05, 30, 5));
  try {
    invert_spacing_for_cohesion(regime, {50.0, {}, {}, std::nullopt});
    ADD_FAILURE() << "expected std::domain_error";
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("thickness H_i is needed"), std::string::npos) << e.what();
  }

  // b = 1: L = a·c/(ρ g) does not involve H, so c follows from L alone.
  const RegimeLaw linear = regime_from_fit("strength", synthetic_study_fit(2.0, 1.0, 0.05, 30, 6));
  const double c = 200e3;
  const double spacing = 2.0 * c / kRhoG;
  const CohesionEstimate estimate = invert_spacing_for_cohesion(linear, {spacing, {}, {}, {}});
  EXPECT_TRUE(estimate.thickness_independent);
  EXPECT_TRUE(estimate.interval_pa.contains(c));
  // σ = 0.05 on 30 points pins ln a to ≈ 0.01: 5 % is several standard errors.
  EXPECT_NEAR(estimate.tensile_strength_pa / c, 1.0, 0.05);
  EXPECT_FALSE(estimate.cohesion_ratio_pi.has_value());
  EXPECT_FALSE(estimate.pi_in_regime_range.has_value());
}

TEST(CalibRefusal, OutsideTheStudiedRangeIsRefused) {
  const RegimeLaw regime = regime_from_fit("strength", synthetic_study_fit(0.9, 0.5, 0.05, 30, 8));
  // L/H = 5 is far above a·Π^b ≤ 0.9·1^0.5 over Π ≤ 1.
  EXPECT_THROW(invert_spacing_for_cohesion(regime, {1000.0, {}, {}, 200.0}), std::out_of_range);
  // Π = 1e6/(ρ g·10) ≈ 11, beyond the study's Π ≤ 1.
  EXPECT_THROW(predict_crevasses(regime, 1e6, 10.0), std::out_of_range);
  try {
    invert_spacing_for_cohesion(regime, {1000.0, {}, {}, 200.0});
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("not extrapolated"), std::string::npos) << e.what();
  }
  // A flat law (b ≈ 0) carries no information on c.
  const RegimeLaw flat = regime_from_fit("gravity", synthetic_study_fit(0.5, 0.0, 0.05, 30, 9));
  EXPECT_THROW(invert_spacing_for_cohesion(flat, {50.0, {}, {}, 100.0}), std::domain_error);
}

TEST(CalibRefusal, BadObservationsAreRejectedClearly) {
  const RegimeLaw regime = regime_from_fit("strength", synthetic_study_fit(0.9, 0.5, 0.05, 30, 10));
  EXPECT_THROW(invert_spacing_for_cohesion(regime, {-1.0, {}, {}, 100.0}), std::invalid_argument);
  EXPECT_THROW(invert_spacing_for_cohesion(regime, {std::nan(""), {}, {}, 100.0}),
               std::invalid_argument);
  EXPECT_THROW(invert_spacing_for_cohesion(regime, {30.0, 20.0, std::nullopt, 100.0}),
               std::invalid_argument);
  EXPECT_THROW(invert_spacing_for_cohesion(regime, {30.0, 35.0, 40.0, 100.0}),
               std::invalid_argument);
  EXPECT_THROW(invert_spacing_for_cohesion(regime, {30.0, {}, {}, 0.0}), std::invalid_argument);
  EXPECT_THROW(predict_crevasses(regime, 0.0, 100.0), std::invalid_argument);
}

TEST(CalibRegimes, ReportsWhetherTheEstimateIsSelfConsistent) {
  // A hand-made regime L/H = Π on Π ∈ [0.1, 1] whose cases scattered up to L/H = 2.
  RegimeLaw regime;
  regime.name = "hand-made";
  regime.pi_min = 0.1;
  regime.pi_max = 1.0;
  regime.spacing_ratio_min = 0.05;
  regime.spacing_ratio_max = 2.0;
  regime.spacing = PowerLaw{0.0, 1.0, {1e-4, 0.0, 1e-4}, 1e-3, 20.0};
  const CohesionEstimate estimate = invert_spacing_for_cohesion(regime, {150.0, {}, {}, 100.0});
  EXPECT_NEAR(estimate.cohesion_ratio_pi->value, 1.5, 1e-12);  // Π = L/H for a = b = 1
  EXPECT_FALSE(*estimate.pi_in_regime_range);
  EXPECT_FALSE(*estimate.pi_interval_in_regime_range);
}

TEST(CalibRegimes, BrokenLineGivesTwoInvertibleRegimes) {
  // L/H = 2·(Π/0.1)^b, b = 1 below Π* = 0.1 and 0.3 above, σ = 0.05.
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<double> pi, ratio;
  for (int i = 0; i < 40; ++i) {
    pi.push_back(std::pow(10.0, -3.0 + 3.0 * i / 39.0));
    ratio.push_back(2.0 * std::pow(pi.back() / 0.1, pi.back() < 0.1 ? 1.0 : 0.3) *
                    std::exp(noise(rng)));
  }
  const std::vector<RegimeLaw> regimes =
      regimes_from_broken_line(fit_broken_line(pi, ratio), "strength", "overburden");
  ASSERT_EQ(regimes.size(), 2u);
  EXPECT_NEAR(regimes[0].pi_max, regimes[1].pi_min, 0.0);
  const double h = 100.0, c_low = 0.01 * kRhoG * h;     // Π = 0.01, strength regime
  const double spacing = 2.0 * std::pow(0.1, 1.0) * h;  // L/H = 0.2
  const std::vector<CohesionEstimate> estimates =
      invert_spacing_in_all_regimes(regimes, {spacing, {}, {}, h});
  ASSERT_FALSE(estimates.empty());
  EXPECT_EQ(estimates.front().regime, "strength");
  EXPECT_TRUE(estimates.front().interval_pa.contains(c_low));
  EXPECT_TRUE(*estimates.front().pi_in_regime_range);
  EXPECT_THROW(invert_spacing_in_all_regimes(regimes, {1e5, {}, {}, h}), std::out_of_range);
}

}  // namespace
}  // namespace crevasse::analysis
