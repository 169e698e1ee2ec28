// Tests of nelder_mead.cc. Every expected minimiser is known by hand: Rosenbrock's (1, 1), the
// centre of a quadratic bowl, and the edge of an admissible region.
#include "leglab/model/nelder_mead.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace leglab {
namespace {

// Rosenbrock's function (1 - x)^2 + 100 (y - x^2)^2: minimum 0 at (1, 1), in a curved valley.
double Rosenbrock(const std::vector<double>& p) {
  const double x = p[0];
  const double y = p[1];
  return (1.0 - x) * (1.0 - x) + 100.0 * (y - x * x) * (y - x * x);
}

TEST(NelderMead, FindsRosenbrocksMinimum) {
  std::vector<double> x = {-1.2, 1.0};
  const double value = NelderMead(Rosenbrock, x, {0.1, 0.1}, 5000);
  EXPECT_NEAR(x[0], 1.0, 1e-6);
  EXPECT_NEAR(x[1], 1.0, 1e-6);
  EXPECT_LT(value, 1e-12);
  EXPECT_EQ(value, Rosenbrock(x));  // the value returned is f at the point written
}

TEST(NelderMead, FindsTheCentreOfAQuadraticBowl) {
  // 5 + (x - 3)^2 + 10 (y + 1)^2 + 0.5 (z - 0.25)^2: minimum 5 at (3, -1, 0.25).
  auto bowl = [](const std::vector<double>& p) {
    return 5.0 + (p[0] - 3.0) * (p[0] - 3.0) + 10.0 * (p[1] + 1.0) * (p[1] + 1.0) +
           0.5 * (p[2] - 0.25) * (p[2] - 0.25);
  };
  std::vector<double> x = {0.0, 0.0, 0.0};
  const double value = NelderMead(bowl, x, {0.5, 0.5, 0.5}, 5000);
  // f resolves the bowl's floor only to about sqrt(5 eps) ~ 3e-8 in each coordinate.
  EXPECT_NEAR(x[0], 3.0, 1e-6);
  EXPECT_NEAR(x[1], -1.0, 1e-6);
  EXPECT_NEAR(x[2], 0.25, 1e-6);
  EXPECT_NEAR(value, 5.0, 1e-12);
}

TEST(NelderMead, StopsWhenTheSimplexIsSmallerThanTheTolerance) {
  // One variable, (x - 2)^2: with a coarse tolerance it stops near 2 but not at it.
  auto parabola = [](const std::vector<double>& p) { return (p[0] - 2.0) * (p[0] - 2.0); };
  std::vector<double> coarse = {0.0};
  NelderMead(parabola, coarse, {1.0}, 1000, 1e-2);
  EXPECT_NEAR(coarse[0], 2.0, 1e-2);
  std::vector<double> fine = {0.0};
  NelderMead(parabola, fine, {1.0}, 1000);
  EXPECT_NEAR(fine[0], 2.0, 1e-8);
}

TEST(NelderMead, NeverGoesWhereTheObjectiveIsInfinite) {
  // (x + 1)^2 on x >= 0 only: the minimiser is the edge, 0.
  int evaluations_outside = 0;
  auto constrained = [&](const std::vector<double>& p) {
    if (p[0] < 0.0) {
      ++evaluations_outside;
      return std::numeric_limits<double>::infinity();
    }
    return (p[0] + 1.0) * (p[0] + 1.0);
  };
  std::vector<double> x = {3.0};
  const double value = NelderMead(constrained, x, {0.5}, 1000);
  EXPECT_GE(x[0], 0.0);
  EXPECT_LT(x[0], 1e-6);
  EXPECT_NEAR(value, 1.0, 1e-5);
  EXPECT_GT(evaluations_outside, 0);  // it did try beyond the edge, and stayed inside
}

TEST(NelderMead, ZeroIterationsReturnsTheBestVertexOfTheFirstSimplex) {
  auto parabola = [](const std::vector<double>& p) { return (p[0] - 2.0) * (p[0] - 2.0); };
  std::vector<double> x = {0.0};
  EXPECT_EQ(NelderMead(parabola, x, {1.0}, 0), 1.0);  // the vertex x + step = 1
  EXPECT_EQ(x[0], 1.0);
}

TEST(NelderMead, IsDeterministic) {
  std::vector<double> a = {-1.2, 1.0};
  std::vector<double> b = {-1.2, 1.0};
  EXPECT_EQ(NelderMead(Rosenbrock, a, {0.1, 0.1}, 300), NelderMead(Rosenbrock, b, {0.1, 0.1}, 300));
  EXPECT_EQ(a, b);
}

}  // namespace
}  // namespace leglab
