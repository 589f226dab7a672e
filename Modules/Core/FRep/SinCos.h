// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// sin and cos without libm, with a proven bound on their error, for the ends of interval sin and
// cos (Evaluators.cxx's trigRange): a libm call costs about as much as the rest of an interval
// instruction, and an interval needs an enclosure, not a correctly rounded value.
//
// Method: x = k pi/2 + r with k the integer nearest x 2/pi and |r| <= pi/4 (plus 2^-30 for the
// rounding of x 2/pi), r computed by Cody and Waite's reduction with pi/2 = C1 + C2 + C3, where C1
// has 31 significant bits and C2 32, so that k C1 and k C2 are exact for |k| <= 2^20; then the
// Taylor polynomials of sin (to r^15) and cos (to r^16) at r, by Horner's rule, and the quadrant
// k mod 4 picks sin r, cos r, -sin r or -cos r.
//
// The bound (|x| <= SinCosLimit = 2^20; u = 2^-53, the unit roundoff):
// - reduction: x - k C1 is exact: k = 0 leaves x; otherwise |x| >= 0.78, k C1 is a multiple of
//   2^-30 and so of ulp(x) (at most 2^-33 below 2^20), and the difference, at most 0.79, is
//   below 2^53 ulp(x). t - k C2 and the subtraction of fl(k C3) round once each, by at most
//   u |r| <= 8.8e-17 each; fl(k C3) errs by at most u 2^20 2^-65 and pi/2 - C1 - C2 - C3 is
//   1.0e-37, times |k| <= 2^20: negligible. |r - r_exact| <= 1.8e-16, which moves sin and cos
//   by at most as much (their derivatives are at most 1 in size).
// - truncation of the series (alternating, terms decreasing for |r| <= 0.786): at most the
//   first term left out, (pi/4)^17 / 17! = 4.6e-17 for sin, (pi/4)^18 / 18! = 2e-18 for cos.
// - evaluation: sin r = r + (r r^2) p(r^2) with |r^3 p| <= 0.081, whose value carries at most
//   6u of relative error (r^2, the product, p's Horner steps, dominated by its last terms, and
//   its rounded coefficients): 5.4e-17; the last addition rounds by at most u |sin r| <= 7.9e-17.
//   cos r = (1 - r^2/2) + r^4 q(r^2): r^2/2 errs by 3.4e-17, 1 - r^2/2 rounds by 5.6e-17,
//   r^4 q (at most 0.016) by 1.1e-17, the last addition by 1.1e-16.
// Sum: |sinApprox(x) - sin x| <= 3.6e-16 and |cosApprox(x) - cos x| <= 3.9e-16, below
// SinCosError = 4e-16. The point evaluators call libm, which is faithful (within an ulp, 1.1e-16
// for values of at most 1), so libm's value lies within SinCosError + 1.1e-16 < 2^-50 of these;
// the interval bounds are widened by SinCosWidening = 2^-50 (and then by an ulp, for the
// subtraction's own rounding). Testing/Core/TestEvaluators.cxx checks the bound against long
// double over random and near-multiple-of-pi/2 arguments.

#include <cstdint>

namespace ictk::frep::detail
{

/// The arguments (in size) the approximations below hold their bound for.
constexpr double SinCosLimit = 0x1p20;
/// The proven bound on their error against the exact sin and cos.
constexpr double SinCosError = 4e-16;
/// How far interval bounds from them are moved outwards to enclose libm's values too.
constexpr double SinCosWidening = 0x1p-50;

namespace sincos
{
// pi/2 = C1 + C2 + C3 (C1: 31 significant bits, C2: 32).
constexpr double C1 = 0x1.921fb544p+0;
constexpr double C2 = 0x1.0b4611a6p-34;
constexpr double C3 = 0x1.3198a2e037073p-69;
constexpr double TwoOverPi = 0x1.45f306dc9c883p-1;
// Rounds to the nearest integer by adding and subtracting 1.5 2^52 (|values| < 2^51).
constexpr double Shifter = 0x1.8p52;

// x = k pi/2 + r; returns r and sets the quadrant k mod 4.
inline double reduce(double x, unsigned& quadrant)
{
  const double k = (x * TwoOverPi + Shifter) - Shifter;
  quadrant = static_cast<unsigned>(static_cast<std::int64_t>(k)) & 3u;
  return ((x - k * C1) - k * C2) - k * C3;
}

// The Taylor polynomials, |r| <= pi/4 + 2^-30; coefficients 1/n! rounded to double.
inline double sinSeries(double r)
{
  const double r2 = r * r;
  double p = -0x1.ae7f3e733b81fp-41;  // -1/15!
  p = p * r2 + 0x1.6124613a86d09p-33; // 1/13!
  p = p * r2 - 0x1.ae64567f544e4p-26; // -1/11!
  p = p * r2 + 0x1.71de3a556c734p-19; // 1/9!
  p = p * r2 - 0x1.a01a01a01a01ap-13; // -1/7!
  p = p * r2 + 0x1.1111111111111p-7;  // 1/5!
  p = p * r2 - 0x1.5555555555555p-3;  // -1/3!
  return r + (r * r2) * p;
}

inline double cosSeries(double r)
{
  const double r2 = r * r;
  double q = 0x1.ae7f3e733b81fp-45;   // 1/16!
  q = q * r2 - 0x1.93974a8c07c9dp-37; // -1/14!
  q = q * r2 + 0x1.1eed8eff8d898p-29; // 1/12!
  q = q * r2 - 0x1.27e4fb7789f5cp-22; // -1/10!
  q = q * r2 + 0x1.a01a01a01a01ap-16; // 1/8!
  q = q * r2 - 0x1.6c16c16c16c17p-10; // -1/6!
  q = q * r2 + 0x1.5555555555555p-5;  // 1/4!
  return (1 - 0.5 * r2) + (r2 * r2) * q;
}

inline double inQuadrant(double r, unsigned quadrant)
{
  switch (quadrant)
  {
    case 0:
      return sinSeries(r);
    case 1:
      return cosSeries(r);
    case 2:
      return -sinSeries(r);
    default:
      return -cosSeries(r);
  }
}
} // namespace sincos

/// sin x within SinCosError, for |x| <= SinCosLimit.
inline double sinApprox(double x)
{
  unsigned quadrant = 0;
  const double r = sincos::reduce(x, quadrant);
  return sincos::inQuadrant(r, quadrant);
}

/// cos x = sin(x + pi/2) within SinCosError, for |x| <= SinCosLimit.
inline double cosApprox(double x)
{
  unsigned quadrant = 0;
  const double r = sincos::reduce(x, quadrant);
  return sincos::inQuadrant(r, (quadrant + 1) & 3u);
}

} // namespace ictk::frep::detail
