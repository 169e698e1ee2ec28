#pragma once

// The sine and cosine of an angle in degrees, for the extended model's load (m g L sin M), which
// its fit evaluates once a tick of every rollout. The angle is reduced in degrees, where the
// reduction is exact (sin 180 is 0, not 1.2e-16), and the remainder of at most 45 deg goes
// through the minimax polynomials of fdlibm's k_sin.c and k_cos.c (Sun Microsystems, "freely
// granted"; the same in musl): within two units in the last place, branch-free apart from the
// quadrant, and inline, so that rollouts side by side overlap. Why not std::sin: it is a call
// that costs as much as the rest of the model's tick (docs/design/log-fit-cost.md). Internal to
// leglab::servo.

#include <cmath>
#include <cstdint>
#include <numbers>

#include "leglab/model/internal/lanes.h"

// The kernels and SinDegrees take and return Lanes too, always inlined (see lanes.h).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace leglab::servo_tick {

namespace detail {

// sin x for |x| <= pi/4 (fdlibm's __kernel_sin with no tail), for a double or Lanes (lane by
// lane the same operations, so the same bits).
template <typename T>
[[gnu::always_inline]] inline T SineKernel(T x) {
  constexpr double kS1 = -1.66666666666666324348e-01;
  constexpr double kS2 = 8.33333333332248946124e-03;
  constexpr double kS3 = -1.98412698298579493134e-04;
  constexpr double kS4 = 2.75573137070700676789e-06;
  constexpr double kS5 = -2.50507602534068634195e-08;
  constexpr double kS6 = 1.58969099521155010221e-10;
  const T z = x * x;
  const T r = kS2 + z * (kS3 + z * (kS4 + z * (kS5 + z * kS6)));
  return x + z * x * (kS1 + z * r);
}

// cos x for |x| <= pi/4 (fdlibm's __kernel_cos with no tail, in musl's form), for a double or
// Lanes.
template <typename T>
[[gnu::always_inline]] inline T CosineKernel(T x) {
  constexpr double kC1 = 4.16666666666666019037e-02;
  constexpr double kC2 = -1.38888888888741095749e-03;
  constexpr double kC3 = 2.48015872894767294178e-05;
  constexpr double kC4 = -2.75573143513906633035e-07;
  constexpr double kC5 = 2.08757232129817482790e-09;
  constexpr double kC6 = -1.13596475577881948265e-11;
  const T z = x * x;
  const T r = z * (kC1 + z * (kC2 + z * (kC3 + z * (kC4 + z * (kC5 + z * kC6)))));
  const T half_z = 0.5 * z;
  const T w = 1.0 - half_z;
  return w + (((1.0 - w) - half_z) + z * r);
}

// Angles beyond this many degrees (and NaN) go to std::sin / std::cos.
inline constexpr double kReducedLimitDeg = 1e15;

// `deg` = 90 k + r with k an integer and |r| <= 45 (r exact): returns r in radians, k mod 4.
inline double ReduceDegrees(double deg, int& quadrant) {
  constexpr double kRound = 0x1.8p52;  // adding and taking it off rounds to an integer
  const double k = (deg * (1.0 / 90.0) + kRound) - kRound;  // |deg - 90 k| <= 45 + 1e-14
  quadrant = static_cast<int>(static_cast<int64_t>(k) & 3);
  return (deg - 90.0 * k) * (std::numbers::pi / 180.0);
}

// sin(90 quadrant deg + x rad) for quadrant in 0..3 (any integer: taken mod 4).
inline double SineOfQuadrant(int quadrant, double x) {
  switch (quadrant & 3) {
    case 0:
      return SineKernel(x);
    case 1:
      return CosineKernel(x);
    case 2:
      return -SineKernel(x);
    default:
      return -CosineKernel(x);
  }
}

}  // namespace detail

/// sin(deg pi / 180), within two units in the last place; exactly 0 at multiples of 180 deg.
inline double SinDegrees(double deg) {
  if (!(std::abs(deg) < detail::kReducedLimitDeg)) return std::sin(deg * std::numbers::pi / 180.0);
  int quadrant = 0;
  const double x = detail::ReduceDegrees(deg, quadrant);
  return detail::SineOfQuadrant(quadrant, x);
}

/// The lanes whose angle SinDegrees reduces in degrees (the others go to std::sin).
[[gnu::always_inline]] inline LaneMask InReducedRange(Lanes deg) {
  return Abs(deg) < detail::kReducedLimitDeg;
}

/// SinDegrees of each lane, the same bits, for lanes all InReducedRange: both kernels are
/// computed in every lane and the quadrant's taken without a branch.
[[gnu::always_inline]] inline Lanes SinDegreesInRange(Lanes deg) {
  constexpr double kRound = 0x1.8p52;  // as in ReduceDegrees
  const Lanes shifted = deg * (1.0 / 90.0) + kRound;
  const Lanes k = shifted - kRound;
  // k mod 4 is in the low bits of `shifted`, whose significand holds 2^51 + k (|k| < 2^50).
  const auto quadrant = __builtin_bit_cast(LaneBits, shifted);
  const Lanes x = (deg - 90.0 * k) * (std::numbers::pi / 180.0);
  const LaneMask odd = -__builtin_bit_cast(LaneMask, quadrant & 1);  // all ones in quadrants 1, 3
  const Lanes sine = Select(odd, detail::CosineKernel(x), detail::SineKernel(x));
  return FromBits(Bits(sine) ^
                  __builtin_bit_cast(LaneMask, (quadrant & 2) << 62));  // quadrants 2, 3
}

/// SinDegrees of each lane, the same bits.
[[gnu::always_inline]] inline Lanes SinDegrees(Lanes deg) {
  if (AllLanes(InReducedRange(deg))) return SinDegreesInRange(deg);
  Lanes sine{};
  for (size_t i = 0; i < kLaneCount; ++i) sine[i] = SinDegrees(double{deg[i]});
  return sine;
}

/// cos(deg pi / 180), within two units in the last place; exactly 0 at odd multiples of 90 deg.
inline double CosDegrees(double deg) {
  if (!(std::abs(deg) < detail::kReducedLimitDeg)) return std::cos(deg * std::numbers::pi / 180.0);
  int quadrant = 0;
  const double x = detail::ReduceDegrees(deg, quadrant);
  return detail::SineOfQuadrant(quadrant + 1, x);  // cos a = sin(a + 90 deg)
}

}  // namespace leglab::servo_tick

#pragma GCC diagnostic pop
