#include "leglab/model/joint_model.h"
#include "leglab/model/paper.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace leglab {
namespace {

constexpr JointModelParams kPaper = paper::kTable1;

TEST(SpeedResponse, MatchesEquation2ByHand) {
  EXPECT_DOUBLE_EQ(SpeedResponse(kPaper, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(SpeedResponse(kPaper, 3.5), 1.25);   // half of theta_0 -> half of v_max
  EXPECT_DOUBLE_EQ(SpeedResponse(kPaper, -1.4), -0.5);  // slope 2.5 / 7
  EXPECT_DOUBLE_EQ(SpeedResponse(kPaper, 7.0), 2.5);
  EXPECT_DOUBLE_EQ(SpeedResponse(kPaper, 40.0), 2.5);
  EXPECT_DOUBLE_EQ(SpeedResponse(kPaper, -110.0), -2.5);
}

TEST(JointModel, StepResponseByHand) {
  // From rest at 0, R(t) = 40 for t >= 0. Eq. 3 with l = 4, a = 6 sees R(0) first at t = 5:
  //   M(5) = (1/6) f(40) = 2.5/6;
  //   M(6) = M(5) + (1/6) [2 f(40 - M(5)) + 4 f(0 - M(5))]   (the four older requests are 0)
  //        = 2.5/6 + (5 - 4 (2.5/6)(2.5/7)) / 6.
  std::vector<double> requests(20, 40.0);
  const std::vector<double> m = SimulateJointModel(kPaper, requests, RestState(kPaper, 0.0));
  for (int t = 0; t <= 4; ++t) EXPECT_EQ(m[t], 0.0) << "t = " << t;
  EXPECT_NEAR(m[5], 2.5 / 6.0, 1e-15);
  EXPECT_NEAR(m[6], 2.5 / 6.0 + (5.0 - 4.0 * (2.5 / 6.0) * (2.5 / 7.0)) / 6.0, 1e-15);
  // Once all six remembered requests see the step (t = 10) it moves at top speed.
  EXPECT_NEAR(m[10] - m[9], 2.5, 1e-15);
}

TEST(JointModel, StartsRespondingExactlyLagPlusOneTicksAfterAStep) {
  for (int lag : {0, 1, 4, 9}) {
    const JointModelParams p{2.5, 7.0, lag, 3};
    std::vector<double> requests(30, 0.0);
    for (int t = 7; t < 30; ++t) requests[t] = 10.0;  // the step is requested at t = 7
    const std::vector<double> m = SimulateJointModel(p, requests, RestState(p, 0.0));
    for (int t = 0; t < 7 + lag + 1; ++t) EXPECT_EQ(m[t], 0.0) << "lag " << lag << " t " << t;
    EXPECT_GT(m[7 + lag + 1], 0.0) << "lag " << lag;
  }
}

TEST(JointModel, NeverMovesFasterThanVmax) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-120.0, 120.0);
  std::vector<double> requests(2000);
  for (double& r : requests) r = angle(rng);
  const std::vector<double> m = SimulateJointModel(kPaper, requests, RestState(kPaper, 0.0));
  double fastest = 0.0;
  for (size_t t = 1; t < m.size(); ++t) fastest = std::max(fastest, std::abs(m[t] - m[t - 1]));
  EXPECT_LE(fastest, 2.5 + 1e-12);
  EXPECT_GT(fastest, 2.4);  // random jumps of up to 240 deg do drive it to its top speed
}

TEST(JointModel, StepAndSimulateAgree) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-50.0, 50.0);
  std::vector<double> requests(300);
  for (double& r : requests) r = angle(rng);
  JointModelState state = RestState(kPaper, 5.0);
  const std::vector<double> simulated = SimulateJointModel(kPaper, requests, state);
  for (size_t t = 0; t < requests.size(); ++t) {
    ASSERT_EQ(StepJointModel(kPaper, state, requests[t]), simulated[t]) << "t = " << t;
  }
}

TEST(JointModel, CyclicSteadyStateIsTheLimitOfRepeatingTheCycle) {
  // Brute force: 200 cycles from rest at 0, compared with the last one.
  std::vector<double> cycle(88);
  for (int t = 0; t < 88; ++t) cycle[t] = 50.0 * std::sin(2.0 * M_PI * t / 88.0) + 10.0;
  std::vector<double> repeated;
  for (int k = 0; k < 200; ++k) repeated.insert(repeated.end(), cycle.begin(), cycle.end());
  const std::vector<double> m = SimulateJointModel(kPaper, repeated, RestState(kPaper, 0.0));
  const std::vector<double> steady = CyclicSteadyState(kPaper, cycle);
  ASSERT_EQ(steady.size(), 88u);
  for (int t = 0; t < 88; ++t) EXPECT_NEAR(steady[t], m[m.size() - 88 + t], 1e-9) << "t " << t;
}

TEST(JointModel, CyclicSteadyStateOfAConstantIsThatConstant) {
  const std::vector<double> cycle(20, -33.0);
  for (double angle : CyclicSteadyState(kPaper, cycle)) EXPECT_NEAR(angle, -33.0, 1e-12);
}

TEST(JointModel, RejectsBadParameters) {
  EXPECT_THROW(RestState({0.0, 7.0, 4, 6}, 0.0), std::invalid_argument);
  EXPECT_THROW(RestState({2.5, -1.0, 4, 6}, 0.0), std::invalid_argument);
  EXPECT_THROW(RestState({2.5, 7.0, -1, 6}, 0.0), std::invalid_argument);
  EXPECT_THROW(RestState({2.5, 7.0, 4, 0}, 0.0), std::invalid_argument);
  EXPECT_THROW(CyclicSteadyState(kPaper, std::vector<double>{}), std::invalid_argument);
  JointModelState wrong{0.0, {0.0, 0.0}};
  EXPECT_THROW(SimulateJointModel(kPaper, std::vector<double>(3, 1.0), wrong),
               std::invalid_argument);
}

}  // namespace
}  // namespace leglab
