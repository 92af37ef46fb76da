#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "analysis/regime_diagram.hpp"

namespace crevasse::analysis {
namespace {

// Nye (1957): a crevasse closes where the overburden ρ_i g D equals twice the tensile strength
// c, so D/H_i = 2c/(ρ_i g H_i) = 2Π, and no crevasse is deeper than the ice.
TEST(NyeDepth, RisesAsTwicePiAndStopsAtTheBed) {
  const ReferenceCurve nye = nye_zero_stress_depth(0.05, 1.0, 64);
  ASSERT_EQ(nye.x.size(), 65u);
  ASSERT_EQ(nye.y.size(), 65u);
  EXPECT_DOUBLE_EQ(nye.x.front(), 0.05);
  EXPECT_NEAR(nye.x.back(), 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(nye.y.front(), 0.1);  // Π = 0.05: D/H_i = 0.1
  EXPECT_DOUBLE_EQ(nye.y.back(), 1.0);   // Π = 1: capped at the bed, not 2
  bool below = false, capped = false;
  for (std::size_t i = 0; i < nye.x.size(); ++i) {
    if (nye.x[i] < 0.5) {
      EXPECT_NEAR(nye.y[i], 2.0 * nye.x[i], 1e-15) << "at Π = " << nye.x[i];
      below = true;
    } else {
      EXPECT_EQ(nye.y[i], 1.0) << "at Π = " << nye.x[i];
      capped = true;
    }
    if (i > 0) {
      EXPECT_NEAR(nye.x[i] / nye.x[i - 1], std::pow(20.0, 1.0 / 64), 1e-12);  // log-even
    }
  }
  EXPECT_TRUE(below && capped);
  EXPECT_NE(nye.legend.find("Nye"), std::string::npos);
}

TEST(NyeDepth, RefusesAnEmptyOrNonPositiveRange) {
  EXPECT_THROW(nye_zero_stress_depth(0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(nye_zero_stress_depth(0.5, 0.1), std::invalid_argument);
  EXPECT_THROW(nye_zero_stress_depth(0.1, 1.0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace crevasse::analysis
