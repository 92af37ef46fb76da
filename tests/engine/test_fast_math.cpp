// pow_half must return exactly what glibc's pow(x, 0.5) returns: the engine uses it in place of
// pow and its results must not change by a bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "engine/fast_math.hpp"

namespace crevasse {
namespace {

::testing::AssertionResult same_bits(double x) {
  const double want = std::pow(x, 0.5), got = pow_half(x);
  if (std::bit_cast<std::uint64_t>(want) == std::bit_cast<std::uint64_t>(got) ||
      (std::isnan(want) && std::isnan(got)))
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "x = " << std::hexfloat << x << ": pow " << want
                                       << ", pow_half " << got;
}

// The engine's arguments: ratios ΔJ̄/ΔJ of a step, within 1e-9 … 1e-1 of 1.
TEST(PowHalf, SameBitsAsPowNearOne) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0), e(-9.0, -1.0);
  long sqrt_differs = 0;
  const long n = 2'000'000;
  for (long i = 0; i < n; ++i) {
    const double x = 1.0 + u(rng) * std::pow(10.0, e(rng));
    ASSERT_TRUE(same_bits(x));
    const double s = std::sqrt(x);
    sqrt_differs += std::bit_cast<std::uint64_t>(s) != std::bit_cast<std::uint64_t>(std::pow(x, 0.5));
  }
  // sqrt and pow do differ for some of these (pow is not correctly rounded), so the test would
  // fail for a pow_half that simply returned sqrt(x).
  EXPECT_GT(sqrt_differs, 0);
}

TEST(PowHalf, SameBitsAsPowOverTheWholeRange) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::uint64_t> bits(0, 0x7fefffffffffffffull);
  for (long i = 0; i < 1'000'000; ++i) ASSERT_TRUE(same_bits(std::bit_cast<double>(bits(rng))));
  // Powers of two (the gap below is half the gap above), their neighbours, and the edges.
  for (int k = -1074; k <= 1023; ++k) {
    const double x = std::ldexp(1.0, k);
    ASSERT_TRUE(same_bits(x));
    ASSERT_TRUE(same_bits(std::nextafter(x, 0.0)));
    ASSERT_TRUE(same_bits(std::nextafter(x, 2.0 * x)));
  }
  for (double x : {0.0, -0.0, -1.0, 0x1p-500, 0x1p500, std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::max(),
                   std::numeric_limits<double>::quiet_NaN()})
    EXPECT_TRUE(same_bits(x));
}

// floor_to_int is (int)std::floor over the range the stencils use: the integers themselves, their
// neighbours on both sides of zero, the halves (where xi − 0.5 of a stencil lands on an integer)
// and random values. A version that forgets the correction for negative numbers fails on −0.5.
TEST(FloorToInt, SameIntegerAsFloor) {
  const auto check = [](double t) {
    ASSERT_EQ(floor_to_int(t), static_cast<int>(std::floor(t))) << t;
  };
  for (int k = -100000; k <= 100000; ++k) {
    const double t = k;
    check(t);
    check(std::nextafter(t, -1e9));
    check(std::nextafter(t, 1e9));
    check(t + 0.5);
    check(-(t + 0.5));
  }
  check(0.0);
  check(-0.0);
  check(std::numeric_limits<double>::denorm_min());
  check(-std::numeric_limits<double>::denorm_min());
  check(2147483647.0);
  check(-2147483648.0);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1e6, 1e6);
  for (int i = 0; i < 1000000; ++i) check(u(rng));
}

}  // namespace
}  // namespace crevasse
