#include "leglab/model/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace leglab {
namespace {

TEST(Metrics, HandCheckedDistances) {
  const std::vector<double> a{1.0, 2.0, 3.0};
  const std::vector<double> b{1.0, 0.0, 3.0};  // differences 0, 2, 0
  EXPECT_DOUBLE_EQ(RmsDistance(a, b), std::sqrt(4.0 / 3.0));
  EXPECT_DOUBLE_EQ(MaxAbsDistance(a, b), 2.0);
  const std::vector<double> c{-3.0, 4.0};
  EXPECT_DOUBLE_EQ(Rms(c), std::sqrt(12.5));
  EXPECT_DOUBLE_EQ(MaxAbs(c), 4.0);
}

TEST(Metrics, RmsIsBelowMaxAbs) {
  const std::vector<double> a{0.5, -2.0, 7.0, 1.0};
  const std::vector<double> zero(4, 0.0);
  EXPECT_LT(RmsDistance(a, zero), MaxAbsDistance(a, zero));
}

TEST(Metrics, MeanAndSampleStd) {
  const std::vector<double> v{1.0, 2.0, 3.0, 4.0};
  const MeanStd s = MeanAndStd(v);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(5.0 / 3.0));  // squares 2.25+0.25+0.25+2.25 = 5 over n-1
  const MeanStd one = MeanAndStd(std::vector<double>{4.2});
  EXPECT_DOUBLE_EQ(one.mean, 4.2);
  EXPECT_EQ(one.std, 0.0);
}

TEST(Metrics, RejectsMismatchedOrEmpty) {
  EXPECT_THROW(RmsDistance(std::vector<double>{1.0}, std::vector<double>{1.0, 2.0}),
               std::invalid_argument);
  EXPECT_THROW(MaxAbsDistance(std::vector<double>{}, std::vector<double>{}), std::invalid_argument);
  EXPECT_THROW(MeanAndStd(std::vector<double>{}), std::invalid_argument);
}

}  // namespace
}  // namespace leglab
