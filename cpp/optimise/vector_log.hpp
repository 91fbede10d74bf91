// ln x written without a branch or a library call, so that the optimiser's loops over quadrature
// points vectorise through it (glibc's log is one call per point: a tenth of a sweep's time on
// the long cylinder, order 4).
//
// The method is the classical one: x = 2^k m with sqrt(1/2) <= m < sqrt(2) (read from the bits),
// f = m - 1 exactly, and ln(1 + f) = 2 atanh(s) with s = f / (2 + f), |s| <= 0.1716, written as
// f - f^2/2 + s (f^2/2 + R(s^2)) so that the large terms are exact; R's series
// 2/3 z + 2/5 z^2 + ... is summed to z^10, whose remainder (below 1.2e-18 relative) lies under the
// last place. k ln 2 is added in two parts, the first with trailing zeros so that k times it is
// exact. The error is within about one unit in the last place, as glibc's own; the unit tests
// measure it against std::log over the whole range of doubles.
#pragma once

#include <cstdint>
#include <cstring>
#include <limits>

namespace homesh {

// ln x for x > 0, including subnormal x and +infinity. Unspecified (but no trap) for x <= 0 and
// NaN: callers select such points away.
[[gnu::always_inline]] inline double vectorLog(double x) {
  constexpr double kTwo54 = 18014398509481984.0;              // 2^54, scales a subnormal x
  constexpr double kTwo52 = 4503599627370496.0;               // 2^52, for the exponent as a double
  constexpr std::uint64_t kSqrtHalf = 0x3fe6a09e667f3bcdULL;  // the bits of sqrt(1/2)
  constexpr std::uint64_t kOne = 0x3ff0000000000000ULL;       // the bits of 1
  constexpr std::uint64_t kMantissa = 0x000fffffffffffffULL;
  constexpr double kLn2High = 0x1.62e42feep-1;       // ln 2 to 32 bits: k kLn2High is exact
  constexpr double kLn2Low = 0x1.a39ef35793c76p-33;  // ln 2 - kLn2High
  const bool tiny = x < std::numeric_limits<double>::min();
  const double y = tiny ? x * kTwo54 : x;
  std::uint64_t bits = 0;
  std::memcpy(&bits, &y, sizeof bits);
  // Adding 1 - sqrt(1/2) carries into the exponent exactly when the significand is at least
  // sqrt(2); the mantissa then restored around sqrt(1/2) gives m in [sqrt(1/2), sqrt(2)).
  bits += kOne - kSqrtHalf;
  // The exponent field as a double (2^52 + e read back, less 2^52): no integer conversion, which
  // has no vector instruction before AVX-512.
  std::uint64_t exponentBits = (bits >> 52) | 0x4330000000000000ULL;
  double e = 0.0;
  std::memcpy(&e, &exponentBits, sizeof e);
  const double k = (e - kTwo52) - (tiny ? 1023.0 + 54.0 : 1023.0);
  bits = (bits & kMantissa) + kSqrtHalf;
  double m = 0.0;
  std::memcpy(&m, &bits, sizeof m);
  const double f = m - 1.0;
  const double s = f / (2.0 + f);
  const double z = s * s;
  const double r =
      z * (2.0 / 3 +
           z * (2.0 / 5 +
                z * (2.0 / 7 +
                     z * (2.0 / 9 +
                          z * (2.0 / 11 +
                               z * (2.0 / 13 +
                                    z * (2.0 / 15 +
                                         z * (2.0 / 17 + z * (2.0 / 19 + z * (2.0 / 21))))))))));
  const double halfSquare = 0.5 * f * f;
  const double value = k * kLn2High - ((halfSquare - (s * (halfSquare + r) + k * kLn2Low)) - f);
  return x == std::numeric_limits<double>::infinity() ? x : value;
}

}  // namespace homesh
