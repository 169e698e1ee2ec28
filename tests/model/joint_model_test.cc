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

TEST(JointModel, SettlesOnEveryCycleIsVmaxBelowTwiceTheta0) {
  EXPECT_TRUE(SettlesOnEveryCycle(kPaper));  // 2.5 against 14
  EXPECT_TRUE(SettlesOnEveryCycle({1.999, 1.0, 4, 1}));
  EXPECT_FALSE(SettlesOnEveryCycle({2.0, 1.0, 4, 1}));
  EXPECT_FALSE(SettlesOnEveryCycle({3.0, 1.0, 0, 6}));
}

// Below the bound: the steady state CyclicSteadyState returns is a fixed point of the cycle
// (one more cycle of eq. 3 from it, by SimulateJointModel, gives it back), for every window
// and for request cycles that keep f linear, saturate it, or both.
TEST(JointModel, ModelsBelowTheBoundSettleOnRandomCycles) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(-30.0, 30.0);
  for (const double ratio : {0.3, 1.0, 1.5, 1.9}) {
    for (const int accel : {1, 3, 6}) {
      for (const double spread : {0.5, 30.0}) {
        const JointModelParams p{2.0, 2.0 / ratio, 2, accel};
        std::vector<double> cycle(23);
        for (double& r : cycle) r = spread / 30.0 * angle(rng);
        const std::vector<double> steady = CyclicSteadyState(p, cycle);
        // The model's memory at the end of a cycle: the angle and the last l + a requests.
        JointModelState state{steady.back(), {}};
        for (int i = 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
          state.past_requests_deg.push_back(cycle[(cycle.size() * 4 - i) % cycle.size()]);
        }
        const std::vector<double> again = SimulateJointModel(p, cycle, state);
        for (size_t t = 0; t < cycle.size(); ++t) {
          ASSERT_NEAR(again[t], steady[t], 1e-8)
              << "ratio " << ratio << " a " << accel << " spread " << spread << " t " << t;
        }
      }
    }
  }
}

// At and above it a request the model nears is overshot by as much as it was missed, or more:
// started 0.1 deg off a constant request (inside f's linear range), the model is no nearer it
// 200 ticks later, where below the bound it has arrived. Under a square wave of small steps
// such a model (v_max 2.5 theta_0) swings out of step with the cycle, and CyclicSteadyState
// says so.
TEST(JointModel, ModelsAtOrAboveTheBoundSwingForEver) {
  for (const double ratio : {1.0, 1.9, 2.0, 2.5, 4.0}) {
    const JointModelParams p{2.0, 2.0 / ratio, 0, 1};
    JointModelState state = RestState(p, 0.0);
    state.angle_deg = 0.1;
    double angle = 0.0;
    for (int t = 0; t < 200; ++t) angle = StepJointModel(p, state, 0.0);
    if (ratio < 2.0) {
      EXPECT_LT(std::abs(angle), 1e-6) << ratio;
    } else {
      EXPECT_GE(std::abs(angle), 0.1 - 1e-12) << ratio;
    }
  }
  std::vector<double> square(10, 0.0);
  for (int t = 0; t < 5; ++t) square[t] = 0.4;
  EXPECT_THROW(CyclicSteadyState({2.0, 0.8, 1, 1}, square, 1e-10, 2000), std::runtime_error);
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
