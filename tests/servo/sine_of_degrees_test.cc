// The extended model's sine and cosine of degrees against long double's sinl/cosl of an angle
// reduced in long double, over a sweep of angles and at the points the reduction makes exact.

#include "sine_of_degrees.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace leglab::servo_tick {
namespace {

// Exact sin(deg) to about 1e-19 relative: the reduction to [-45, 45] deg is exact in long
// double as it is in double, and sinl of a remainder of at most pi/4 keeps 64 bits.
long double ReferenceSin(double deg, bool cosine) {
  const long double k = std::nearbyint(static_cast<long double>(deg) / 90.0L);
  const long double r = (static_cast<long double>(deg) - 90.0L * k) *
                        (3.14159265358979323846264338327950288L / 180.0L);
  const int quadrant = (static_cast<int>(std::fmod(k, 4.0L)) + 4 + (cosine ? 1 : 0)) % 4;
  switch (quadrant) {
    case 0:
      return std::sin(r);
    case 1:
      return std::cos(r);
    case 2:
      return -std::sin(r);
    default:
      return -std::cos(r);
  }
}

// The error of `value` in units of the last place of the exact result (an ulp of at least the
// smallest normal's, so that results near 0 are held to an absolute 1e-308-scale bound).
double UlpError(double value, long double exact) {
  const double rounded = static_cast<double>(exact);
  const double ulp = std::nextafter(std::abs(rounded), std::numeric_limits<double>::infinity()) -
                     std::abs(rounded);
  return static_cast<double>(std::abs(static_cast<long double>(value) - exact) / ulp);
}

TEST(SinDegrees, IsWithinTwoUlpsOfTheExactSineOverManyAngles) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> near(-400.0, 400.0);
  std::uniform_real_distribution<double> far(-1e7, 1e7);
  double worst_sin = 0.0;
  double worst_cos = 0.0;
  for (int i = 0; i < 400000; ++i) {
    const double deg = i % 4 == 3 ? far(random) : near(random);
    worst_sin = std::max(worst_sin, UlpError(SinDegrees(deg), ReferenceSin(deg, false)));
    worst_cos = std::max(worst_cos, UlpError(CosDegrees(deg), ReferenceSin(deg, true)));
  }
  // Half an ulp from rounding the remainder to radians (std::sin(deg * pi / 180) has the same),
  // the rest the polynomial's.
  EXPECT_LE(worst_sin, 2.0);
  EXPECT_LE(worst_cos, 2.0);
}

TEST(SinDegrees, IsExactWhereTheAngleIsAMultipleOfNinety) {
  for (int k = -40; k <= 40; ++k) {
    const double deg = 90.0 * k;
    const int quadrant = ((k % 4) + 4) % 4;
    const double sine[] = {0.0, 1.0, 0.0, -1.0};
    const double cosine[] = {1.0, 0.0, -1.0, 0.0};
    EXPECT_EQ(SinDegrees(deg), sine[quadrant]) << deg;
    EXPECT_EQ(CosDegrees(deg), cosine[quadrant]) << deg;
  }
}

TEST(SinDegrees, IsOddAndCosDegreesEven) {
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> angle(0.0, 1000.0);
  for (int i = 0; i < 10000; ++i) {
    const double deg = angle(random);
    EXPECT_EQ(SinDegrees(-deg), -SinDegrees(deg)) << deg;
    EXPECT_EQ(CosDegrees(-deg), CosDegrees(deg)) << deg;
  }
}

TEST(SinDegrees, BeyondTheReducedRangeIsTheLibrarySine) {
  EXPECT_EQ(SinDegrees(1e17), std::sin(1e17 * std::numbers::pi / 180.0));
  EXPECT_TRUE(std::isnan(SinDegrees(std::numeric_limits<double>::quiet_NaN())));
  EXPECT_TRUE(std::isnan(CosDegrees(std::numeric_limits<double>::infinity())));
}

}  // namespace
}  // namespace leglab::servo_tick
