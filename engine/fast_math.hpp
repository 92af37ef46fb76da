#pragma once
// Cheaper forms of libm calls that return the very same double as the call they replace, so the
// engine's results stay bit for bit what they were (tests/engine/test_fast_math.cpp,
// bench/state_hash).
#include <bit>
#include <cmath>
#include <cstdint>

namespace crevasse {

// pow(x, 0.5) as glibc's pow returns it, mostly at the price of a square root.
//
// sqrt is correctly rounded; glibc's pow (the Arm optimized-routines pow of glibc ≥ 2.28) is not,
// but its documented worst-case error is 0.54 ULP (glibc sysdeps/ieee754/dbl-64/e_pow.c). So
// when the exact root √x lies within 0.42 of a gap of s = sqrt(x), every other double is at
// least 0.58 gaps from √x and pow can only return s. Where √x lies is found from the exact
// residual x − s² (Dekker's product s² = p + e, with Veltkamp's split; no FMA): √x − s ≈
// (x − s²)/(2s). Otherwise (about 16 % of arguments, those near a rounding midpoint, and any x
// outside [2^-500, 2^500] or not a number) pow itself is called.
// Whether s = sqrt(x) is what pow(x, 0.5) returns, by the test above; no branch, so a loop of
// it vectorises. False for x outside [2^-500, 2^500] (Veltkamp's split would overflow or lose
// bits there) and for NaN.
inline bool sqrt_is_pow_half(double x, double s) {
  const double split = 134217729.0 * s;  // 2^27 + 1
  const double hi = split - (split - s), lo = s - hi;
  const double p = s * s;
  const double e = ((hi * hi - p) + 2.0 * hi * lo) + lo * lo;  // s² − p, exactly
  const double residual = (x - p) - e;                         // x − s²; x − p is exact (Sterbenz)
  // The gap to the next double below s: the smaller of its two gaps (they differ only when s is
  // a power of two), so the test is conservative on both sides.
  const double gap = s - std::bit_cast<double>(std::bit_cast<std::uint64_t>(s) - 1);
  const bool in_range = x >= 0x1p-500 && x <= 0x1p500;
  return in_range & (std::abs(residual) <= 2.0 * 0.42 * s * gap);
}

// (int)std::floor(t) for t inside the range of int, without the call: g++ emits floor, for
// SSE2 without SSE4.1's roundsd, as a chain of converts, compares and masks that sat on the
// critical path of every stencil (perf annotate of P2G). Truncation rounds towards zero, so a
// negative non-integer t truncates one above its floor. The same integer, so the stencil's
// fractional position t − base is the same double. (Outside the range of int, where the cast
// is undefined in both forms, the unsigned step keeps this one from overflowing.)
inline int floor_to_int(double t) {
  const int i = static_cast<int>(t);
  return static_cast<int>(static_cast<unsigned>(i) - static_cast<unsigned>(static_cast<double>(i) > t));
}

inline double pow_half(double x) {
  const double s = std::sqrt(x);
  return sqrt_is_pow_half(x, s) ? s : std::pow(x, 0.5);
}

}  // namespace crevasse
