// The controller contract, split as JointController documents it: checks every registered mode
// must pass (EveryMode), and checks only feed-forward modes must pass (FeedForwardMode), which
// a controller that learns from measurements would fail. Then mode-specific checks.
#include "leglab/controller/controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "leglab/controller/model_based_controller.h"
#include "leglab/controller/optimal_controller.h"
#include "leglab/controller/registry.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/joint_model_plant.h"
#include "leglab/model/metrics.h"
#include "leglab/model/paper.h"
#include "test_context.h"

namespace leglab {
namespace {

using testing::MapOptions;
using testing::PaperContext;
using testing::SpecOf;
using testing::Walkish;

// Requests of `steps` steps of `controller` in closed loop on the ideal plant, with every
// hook called as the experiments call them.
std::vector<LegAngles> ClosedLoopRequests(JointController& controller, const DesiredCycle& desired,
                                          int steps) {
  const std::array<JointModelParams, kLegJoints> models = {paper::kTable1, paper::kTable1,
                                                           paper::kTable1};
  JointModelPlant plant(models, testing::Ers210aLimits());
  plant.Reset(desired[0]);
  controller.Reset();
  std::vector<LegAngles> requests;
  const long period = static_cast<long>(desired.size());
  LegAngles measured = plant.Read().measured_deg;
  for (long t = 0; t < steps * period; ++t) {
    requests.push_back(controller.Update(t, measured));
    const PlantReading& r = plant.Tick(requests.back());
    controller.Observe(t, r.applied_deg, r.measured_deg);
    measured = r.measured_deg;
    if ((t + 1) % period == 0) controller.EndOfStep(t / period);
  }
  return requests;
}

std::vector<std::string> ModeNames(bool feed_forward_only) {
  std::vector<std::string> names;
  for (const ControllerModeInfo& m : ControllerModes()) {
    if (!feed_forward_only || m.feed_forward) names.emplace_back(m.name);
  }
  return names;
}

// Names the instances after the mode (the macro's own parameter is called `info`).
std::string ModeName(const ::testing::TestParamInfo<std::string>& mode) { return mode.param; }

class EveryMode : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryMode, NamesItselfAfterItsMode) {
  const ControllerSpec spec = SpecOf(GetParam());
  EXPECT_EQ(ModeOf(spec).name, GetParam());
  EXPECT_EQ(MakeController(spec, PaperContext(Walkish()))->name(), GetParam());
}

TEST_P(EveryMode, RequestsAreFiniteAndWithinTheLimitsInClosedLoop) {
  // A cycle that asks for the limits themselves: requests must still stay inside.
  DesiredCycle edge = Walkish();
  for (LegAngles& q : edge) q[kKnee] = std::min(147.0, q[kKnee] + 70.0);
  for (const DesiredCycle& desired : {Walkish(), edge}) {
    const auto controller = MakeController(SpecOf(GetParam()), PaperContext(desired));
    const std::array<JointLimits, kLegJoints> limits = testing::Ers210aLimits();
    for (const LegAngles& r : ClosedLoopRequests(*controller, desired, 6)) {
      for (int j = 0; j < kLegJoints; ++j) {
        ASSERT_TRUE(std::isfinite(r[j])) << kLegJointNames[j];
        EXPECT_GE(r[j], RadToDeg(limits[j].lower_rad) - 1e-9) << kLegJointNames[j];
        EXPECT_LE(r[j], RadToDeg(limits[j].upper_rad) + 1e-9) << kLegJointNames[j];
      }
    }
  }
}

TEST_P(EveryMode, SameSpecSameContextSameRequests) {
  const ControllerContext context = PaperContext(Walkish());
  const auto first = MakeController(SpecOf(GetParam()), context);
  const auto second = MakeController(SpecOf(GetParam()), context);
  const std::vector<LegAngles> a = ClosedLoopRequests(*first, context.desired, 4);
  EXPECT_EQ(a, ClosedLoopRequests(*second, context.desired, 4));
  // Reset() starts a new run from scratch: the same requests again.
  EXPECT_EQ(a, ClosedLoopRequests(*first, context.desired, 4));
}

TEST_P(EveryMode, BadOptionsAreAClearErrorNamingTheKey) {
  // Every key the mode reads, given a value no mode accepts.
  MapOptions probe;
  ReadControllerSpec(GetParam(), probe);
  std::map<std::string, std::string> bad;
  for (const auto& [key, count] : probe.read_keys()) bad[key] = "-1000000";
  if (bad.empty()) GTEST_SKIP() << GetParam() << " has no options";
  MapOptions reader(bad);
  try {
    ReadControllerSpec(GetParam(), reader);
    FAIL() << "expected the reader's error";
  } catch (const testing::OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("controller."), std::string::npos) << e.what();
  }
}

TEST_P(EveryMode, EmptyCycleIsAnError) {
  ControllerContext context = PaperContext(Walkish());
  context.desired.clear();
  EXPECT_THROW(MakeController(SpecOf(GetParam()), context), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(Controllers, EveryMode, ::testing::ValuesIn(ModeNames(false)), ModeName);

class FeedForwardMode : public ::testing::TestWithParam<std::string> {};

TEST_P(FeedForwardMode, RequestsRepeatEveryCycleAndIgnoreMeasurements) {
  const auto controller = MakeController(SpecOf(GetParam()), PaperContext(Walkish()));
  for (long t = 0; t < 88; ++t) {
    const LegAngles now = controller->Update(t, {0.0, 0.0, 0.0});
    const LegAngles later = controller->Update(t + 3L * 88, {50.0, -5.0, 100.0});
    EXPECT_EQ(now, later) << "tick " << t;
  }
}

TEST_P(FeedForwardMode, HoldingStillRequestsTheHoldAngle) {
  // A constant desired cycle is a line of slope 0: every policy requests it unchanged
  // (C_0 = 0 for model_based, any shift of a constant is the constant).
  const DesiredCycle still(88, LegAngles{12.0, -3.0, 40.0});
  const auto controller = MakeController(SpecOf(GetParam()), PaperContext(still));
  for (long t = 0; t < 88; ++t) {
    const LegAngles r = controller->Update(t, {0.0, 0.0, 0.0});
    EXPECT_NEAR(r[0], 12.0, 1e-9);
    EXPECT_NEAR(r[1], -3.0, 1e-9);
    EXPECT_NEAR(r[2], 40.0, 1e-9);
  }
}

INSTANTIATE_TEST_SUITE_P(Controllers, FeedForwardMode, ::testing::ValuesIn(ModeNames(true)),
                         ModeName);

TEST(Controllers, DirectRequestsTheDesiredAngles) {
  const DesiredCycle d = Walkish();
  const auto controller = MakeController(SpecOf("direct"), PaperContext(d));
  for (long t = 0; t < 88; ++t) EXPECT_EQ(controller->Update(t, {}), d[t]);
}

TEST(Controllers, TimeShiftLeadsByKTicks) {
  const DesiredCycle d = Walkish();
  const auto controller =
      MakeController(SpecOf("time_shift", {{"shift_ticks", "9"}}), PaperContext(d));
  for (long t = 0; t < 88; ++t) EXPECT_EQ(controller->Update(t, {}), d[(t + 9) % 88]);
  EXPECT_EQ(ModeParameters(SpecOf("time_shift", {{"shift_ticks", "9"}})),
            (std::vector<std::pair<std::string_view, long>>{{"k", 9}}));
}

TEST(Controllers, TimeShiftSearchesEveryDistinctShift) {
  const ControllerContext context = PaperContext(Walkish(20));
  const std::vector<ControllerSpec> candidates = SearchCandidates(SpecOf("time_shift"), context);
  ASSERT_EQ(candidates.size(), 20u);
  for (long k = 0; k < 20; ++k) EXPECT_EQ(ModeParameters(candidates[k])[0].second, k);
  // A mode without a search is its own only candidate.
  EXPECT_EQ(SearchCandidates(SpecOf("direct"), context).size(), 1u);
}

TEST(Controllers, RegistryKnowsEachModesTraits) {
  EXPECT_EQ(ControllerModeNames(), "direct, time_shift, model_based, optimal, ilc, adaptive");
  EXPECT_TRUE(FindControllerMode("adaptive").estimates_model);
  EXPECT_FALSE(FindControllerMode("ilc").estimates_model);
  EXPECT_TRUE(FindControllerMode("time_shift").searchable);
  EXPECT_EQ(FindControllerMode("time_shift").search_file, "shift_search");
  EXPECT_FALSE(FindControllerMode("model_based").searchable);
  EXPECT_TRUE(FindControllerMode("model_based").follows_approximation);
  EXPECT_EQ(FindControllerMode("model_based").label, "MB");
}

TEST(Controllers, UnknownModeListsTheValidOnes) {
  try {
    SpecOf("pid");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(
        e.what(),
        "unknown controller mode 'pid' (valid: direct, time_shift, model_based, optimal, ilc, "
        "adaptive)");
  }
}

TEST(Controllers, ModeOptionsAreValidated) {
  EXPECT_THROW(SpecOf("time_shift", {{"shift_ticks", "-1"}}), testing::OptionError);
  EXPECT_THROW(SpecOf("model_based", {{"cm", "approximate"}}), testing::OptionError);
  EXPECT_EQ(std::get<ModelBasedController::Spec>(SpecOf("model_based", {{"cm", "closed"}})).cm,
            CmMethod::kClosed);
}

TEST(Controllers, ContextRejectsTooManySegments) {
  const std::array<JointModelParams, kLegJoints> models = {paper::kTable1, paper::kTable1,
                                                           paper::kTable1};
  try {
    MakeControllerContext(Walkish(10), models, testing::Ers210aLimits(), 11);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("controller.pwl_segments"), std::string::npos);
  }
}

TEST(Controllers, OfflineCyclesAreComputedOncePerContextAndInputs) {
  // The optimal cycle that optimal and ilc both start from: the second request for the same
  // inputs is served from the context's memo (also to a copy of the context), a copy with
  // another model computes its own.
  const ControllerContext context = PaperContext(Walkish());
  int computed = 0;
  auto compute = [&computed] {
    ++computed;
    return DesiredCycle(3, LegAngles{1.0, 2.0, 3.0});
  };
  const DesiredCycle first = context.offline_cycles->GetOrCompute("optimal", context, compute);
  const ControllerContext copy = context;
  const DesiredCycle again = copy.offline_cycles->GetOrCompute("optimal", copy, compute);
  EXPECT_EQ(computed, 1);
  EXPECT_EQ(again, first);
  ControllerContext other = context;
  other.models[1].lag_ticks += 1;
  other.offline_cycles->GetOrCompute("optimal", other, compute);
  EXPECT_EQ(computed, 2);
  context.offline_cycles->GetOrCompute("another", context, compute);
  EXPECT_EQ(computed, 3);
  // And the real one: the same bits as computed afresh.
  const ControllerContext walk = PaperContext(Walkish());
  const DesiredCycle memoised = OptimalRequestCycle(walk);
  ControllerContext fresh = walk;
  fresh.offline_cycles = std::make_shared<OfflineCycleMemo>();
  EXPECT_EQ(OptimalRequestCycle(fresh), memoised);
  EXPECT_EQ(OptimalRequestCycle(walk), memoised);
}

// The joint optimum as a start (OptimalController::kStartToleranceDeg, what the foot objective
// and ILC start from): its own memo entry, the same bits whichever entry was computed first,
// never worse than the model-based requests it starts from (OptimizeRequests' guarantee), and
// near the optimum solved to the last digit (within 0.01 deg RMS on every joint, a tenth of the
// sensor noise) on a walk fast enough to saturate the joints.
TEST(Controllers, TheOptimumAsAStartIsItsOwnEntryAndNearTheOptimum) {
  const ControllerContext context = PaperContext(Walkish(44));
  const DesiredCycle optimum = OptimalRequestCycle(context);
  const DesiredCycle start = OptimalRequestCycle(context, OptimalController::kStartToleranceDeg);
  ControllerContext fresh = context;
  fresh.offline_cycles = std::make_shared<OfflineCycleMemo>();
  EXPECT_EQ(OptimalRequestCycle(fresh, OptimalController::kStartToleranceDeg), start);
  EXPECT_EQ(OptimalRequestCycle(fresh), optimum);
  EXPECT_NE(start, optimum);  // solved less far: another cycle, not the optimum's entry
  const DesiredCycle model_based = ModelBasedRequestCycle(context, CmMethod::kExact);
  auto rms = [&](const DesiredCycle& requests, int j) {
    std::vector<double> column(requests.size()), desired(requests.size());
    for (size_t t = 0; t < requests.size(); ++t) {
      column[t] = requests[t][j];
      desired[t] = context.desired[t][j];
    }
    return RmsDistance(CyclicSteadyState(context.models[j], column), desired);
  };
  for (int j = 0; j < kLegJoints; ++j) {
    EXPECT_LE(rms(start, j), rms(model_based, j)) << kLegJointNames[j];
    EXPECT_LE(rms(start, j), rms(optimum, j) + 0.01) << kLegJointNames[j];
  }
  EXPECT_THROW(OptimalRequestCycle(context, -1.0), std::invalid_argument);
  EXPECT_THROW(OptimalRequestCycle(context, std::nan("")), std::invalid_argument);
}

// The modes that optimise the model's steady state refuse a model that has none (v_max at least
// 2 theta_0, SettlesOnEveryCycle) with a one-line error naming the mode and the joint, before any
// solve; the paper's modes still run on it.
TEST(Controllers, OptimalAndIlcRefuseAModelWithoutASteadyState) {
  const JointModelParams swings{2.5, 1.25, 4, 1};  // exactly 2 theta_0
  const std::array<JointModelParams, kLegJoints> models = {paper::kTable1, swings, paper::kTable1};
  const ControllerContext context =
      MakeControllerContext(Walkish(), models, testing::Ers210aLimits(), 8);
  for (const std::string mode : {"optimal", "ilc"}) {
    try {
      (void)MakeController(SpecOf(mode), context);
      ADD_FAILURE() << mode << " accepted the model";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()),
                mode +
                    ": the abductor's model has no cyclic steady state (v_max 2.5 deg/tick is "
                    "at least 2 theta_0, 2.5 deg: eq. 3 swings about a request for ever)");
    }
  }
  for (const std::string mode : {"direct", "time_shift", "model_based"}) {
    EXPECT_NO_THROW((void)MakeController(SpecOf(mode), context)) << mode;
  }
}

}  // namespace
}  // namespace leglab
