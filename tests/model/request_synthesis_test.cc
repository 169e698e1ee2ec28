#include "leglab/model/request_synthesis.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "leglab/model/metrics.h"
#include "leglab/model/paper.h"

namespace leglab {
namespace {

constexpr JointModelParams kPaper = paper::kTable1;

TEST(RequestSynthesis, SwitchLeadIsLagPlusHalfTheAccelerationTime) {
  EXPECT_EQ(SwitchLeadTicks(kPaper), 7);            // 4 + 6/2
  EXPECT_EQ(SwitchLeadTicks({2.5, 7.0, 4, 5}), 7);  // 4 + 2.5, rounded half up
  EXPECT_EQ(SwitchLeadTicks({2.5, 7.0, 0, 1}), 1);
}

TEST(RequestSynthesis, TriangleByHand) {
  // P: up from 0 at t = 0 to 40 at t = 40 (slope 1), down to 0 at t = 80 (slope -1).
  const PiecewiseLinear p{80, {0, 40}, {0.0, 40.0}};
  const double c = LineInverseOffsetExact(kPaper, 1.0);  // 9.3 (hand value in its own test)
  const std::vector<double> r = SynthesizeRequests(kPaper, p, CmMethod::kExact);
  // Well inside the rising segment: R = P + C_1.
  EXPECT_NEAR(r[10], 10.0 + c, 1e-12);
  // Seven ticks before the corner the requests already follow the falling line, extended:
  // L_1(33) = 40 - (33 - 40) = 47, R = 47 - C_1.
  EXPECT_NEAR(r[32], 32.0 + c, 1e-12);
  EXPECT_NEAR(r[33], 47.0 - c, 1e-12);
  // Seven ticks before the wrap at t = 80 they switch back to the rising line: L_0(73) = -7.
  EXPECT_NEAR(r[72], 8.0 - c, 1e-12);
  EXPECT_NEAR(r[73], -7.0 + c, 1e-12);
}

TEST(RequestSynthesis, ModelFollowsItsPiecewiseLinearTargetClosely) {
  // A slow triangle (slopes +-1): in the model, the synthesized requests reach P within a
  // fraction of a degree, while requesting P itself lags it by C_1 = 9.3 deg on the lines.
  const PiecewiseLinear p{80, {0, 40}, {0.0, 40.0}};
  const std::vector<double> target = p.Sample();
  const std::vector<double> requests = SynthesizeRequests(kPaper, p, CmMethod::kExact);
  const std::vector<double> model_based = CyclicSteadyState(kPaper, requests);
  const std::vector<double> direct = CyclicSteadyState(kPaper, target);
  EXPECT_LT(RmsDistance(model_based, target), 1.0);
  EXPECT_GT(RmsDistance(direct, target), 5.0);
  // Mid-segment the exact C_m leaves no error once the switch has died out: in f's linear
  // regime the distance to the line contracts by 1 - v/theta_0 = 0.64 a tick, so some 30 ticks
  // after the switch (t = -7) it is below 1e-5 deg.
  EXPECT_NEAR(model_based[35], target[35], 1e-5);
}

TEST(RequestSynthesis, ASegmentShorterThanTheLeadIsStillUsedForItsOwnTicks) {
  // P, period 20: 0 -> 6 over ticks 0..3 (slope 2, 3 ticks, shorter than the 7-tick lead),
  // flat at 6 to tick 10, back to 0 at tick 20 (slope -0.6).
  const PiecewiseLinear p{20, {0, 3, 10}, {0.0, 6.0, 6.0}};
  const double c2 = 20.2;  // exact C_2 for Table 1, as a long ramp run through the model gives
  ASSERT_NEAR(LineInverseOffsetExact(kPaper, 2.0), c2, 1e-9);
  const double c06 = LineInverseOffsetExact(kPaper, -0.6);
  const std::vector<double> r = SynthesizeRequests(kPaper, p, CmMethod::kExact);
  // t = 0: t + 7 = 7 is on the flat segment: R = 6 (C_0 = 0).
  EXPECT_NEAR(r[0], 6.0, 1e-12);
  // t = 12: 19 is on the falling segment, P(19) = 0.6, walked back 7 ticks: 4.8, plus C_-0.6.
  EXPECT_NEAR(r[12], 0.6 + 0.6 * 7.0 + c06, 1e-12);
  // t = 13..15: 20..22 wrap to the short rising segment; P(0) = 0, P(1) = 2, P(2) = 4, walked
  // back 7 ticks at slope 2 (-14), plus C_2.
  EXPECT_NEAR(r[13], 0.0 - 14.0 + c2, 1e-12);
  EXPECT_NEAR(r[14], 2.0 - 14.0 + c2, 1e-12);
  EXPECT_NEAR(r[15], 4.0 - 14.0 + c2, 1e-12);
  // t = 16: 23 -> 3, the flat segment again.
  EXPECT_NEAR(r[16], 6.0, 1e-12);
}

TEST(RequestSynthesis, ATopSpeedSegmentUsesTheThreshold) {
  // 0 -> 25 over ticks 0..10 at exactly v_max = 2.5, then back over 30 ticks.
  const PiecewiseLinear p{40, {0, 10}, {0.0, 25.0}};
  for (CmMethod method : {CmMethod::kExact, CmMethod::kClosed}) {
    const std::vector<double> r = SynthesizeRequests(kPaper, p, method);
    // t = 0: P(7) = 17.5 walked back 7 ticks = 0, plus theta_0 + (l + a) v_max = 32.
    EXPECT_NEAR(r[0], 32.0, 1e-12);
    EXPECT_NEAR(r[2], 5.0 + 32.0, 1e-12);
  }
}

TEST(RequestSynthesis, SlopeAboveVmaxIsAnError) {
  const PiecewiseLinear p{10, {0, 5}, {0.0, 20.0}};  // 4 deg/tick
  EXPECT_THROW(SynthesizeRequests(kPaper, p, CmMethod::kExact), std::invalid_argument);
}

}  // namespace
}  // namespace leglab
