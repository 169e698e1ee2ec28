#include "leglab/controller/controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace leglab {
namespace {

const std::array<JointModelParams, kLegJoints> kPaperModels = {JointModelParams{2.5, 7.0, 4, 6},
                                                               JointModelParams{2.5, 7.0, 4, 6},
                                                               JointModelParams{2.5, 7.0, 4, 6}};

DesiredCycle Walkish(int period = 88) {
  DesiredCycle d(period);
  for (int t = 0; t < period; ++t) {
    const double phase = 2.0 * M_PI * t / period;
    d[t] = {10.0 + 30.0 * std::sin(phase), 15.0 + 8.0 * std::cos(phase),
            60.0 + 25.0 * std::sin(phase + 1.0)};
  }
  return d;
}

class EveryMode : public ::testing::TestWithParam<std::string> {
 protected:
  ControllerSpec Spec() const {
    ControllerSpec spec;
    spec.mode = GetParam();
    spec.shift_ticks = 5;
    return spec;
  }
};

TEST_P(EveryMode, NamesItselfAfterItsMode) {
  EXPECT_EQ(MakeController(Spec(), Walkish(), kPaperModels)->name(), GetParam());
}

TEST_P(EveryMode, RequestsAreFiniteAndRepeatEveryCycle) {
  const auto controller = MakeController(Spec(), Walkish(), kPaperModels);
  const LegAngles measured{0.0, 0.0, 0.0};
  for (long t = 0; t < 88; ++t) {
    const LegAngles now = controller->Update(t, measured);
    const LegAngles later = controller->Update(t + 3L * 88, measured);
    for (int j = 0; j < kLegJoints; ++j) {
      EXPECT_TRUE(std::isfinite(now[j]));
      EXPECT_EQ(now[j], later[j]) << "tick " << t << " joint " << j;
    }
  }
}

TEST_P(EveryMode, HoldingStillRequestsTheHoldAngle) {
  // A constant desired cycle is a line of slope 0: every policy requests it unchanged
  // (C_0 = 0 for model_based, any shift of a constant is the constant).
  const DesiredCycle still(88, LegAngles{12.0, -3.0, 40.0});
  const auto controller = MakeController(Spec(), still, kPaperModels);
  for (long t = 0; t < 88; ++t) {
    const LegAngles r = controller->Update(t, {0.0, 0.0, 0.0});
    EXPECT_NEAR(r[0], 12.0, 1e-9);
    EXPECT_NEAR(r[1], -3.0, 1e-9);
    EXPECT_NEAR(r[2], 40.0, 1e-9);
  }
}

// Names the instances after the mode (the macro's own parameter is called `info`).
std::string ModeName(const ::testing::TestParamInfo<std::string>& mode) { return mode.param; }

INSTANTIATE_TEST_SUITE_P(Controllers, EveryMode, ::testing::ValuesIn(ControllerModes()), ModeName);

TEST(Controllers, DirectRequestsTheDesiredAngles) {
  const DesiredCycle d = Walkish();
  const auto controller = MakeController({.mode = "direct"}, d, kPaperModels);
  for (long t = 0; t < 88; ++t) EXPECT_EQ(controller->Update(t, {}), d[t]);
}

TEST(Controllers, TimeShiftLeadsByKTicks) {
  const DesiredCycle d = Walkish();
  const auto controller = MakeController({.mode = "time_shift", .shift_ticks = 9}, d, kPaperModels);
  for (long t = 0; t < 88; ++t) EXPECT_EQ(controller->Update(t, {}), d[(t + 9) % 88]);
}

TEST(Controllers, UnknownModeListsTheValidOnes) {
  try {
    MakeController({.mode = "pid"}, Walkish(), kPaperModels);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "unknown controller mode 'pid' (valid: direct, time_shift, model_based)");
  }
}

TEST(Controllers, EmptyCycleIsAnError) {
  for (const std::string& mode : ControllerModes()) {
    EXPECT_THROW(MakeController({.mode = mode}, {}, kPaperModels), std::invalid_argument) << mode;
  }
}

}  // namespace
}  // namespace leglab
