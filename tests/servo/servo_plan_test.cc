#include "leglab/servo/servo_plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "horizon_descent.h"  // the optimiser, for the whole-motion optimum (internal)

namespace leglab {
namespace {

constexpr double kTickS = 0.005;
constexpr double kHuge = 1e6;  // deg/s: a speed limit that never binds

// Duty 0.1 per degree of error at kp 10 (saturating at 10 deg), 500 deg/s at full duty.
ServoModelParams Extended(double friction_duty = 0.0, double friction_load_ratio = 0.0) {
  return {.gain_per_deg_kp = 0.01,
          .v_max_deg_s = 500.0,
          .stall_torque_nm = 1.0,
          .friction_duty = friction_duty,
          .friction_load_ratio = friction_load_ratio,
          .velocity_lag_s = 0.03,
          .lag_ticks = 2};
}

double SquaredError(const std::vector<double>& predicted, const std::vector<double>& desired) {
  double sum = 0.0;
  for (size_t t = 0; t < desired.size(); ++t) sum += std::pow(predicted[t] - desired[t], 2);
  return sum;
}

void ExpectWithinLimits(const ServoPlan& plan, double first_deg, const ServoLimits& limits,
                        double tick_s) {
  double previous = first_deg;
  for (size_t t = 0; t < plan.request_deg.size(); ++t) {
    const double r = plan.request_deg[t];
    EXPECT_GE(r, limits.min_deg) << "tick " << t;
    EXPECT_LE(r, limits.max_deg) << "tick " << t;
    EXPECT_LE(std::abs(r - previous), limits.max_speed_deg_s * tick_s + 1e-9) << "tick " << t;
    previous = r;
  }
}

// l = 0, a = 1, v_max = 2, theta_0 = 4: f(x) = x / 2 inside +-4 deg, so reaching 1 deg more in
// one tick takes R = M + 2, and holding takes R = M.
TEST(ServoPlanTest, PaperModelStepOfOneDegreeWorkedByHand) {
  const JointModelParams p{2.0, 4.0, 0, 1};
  const std::vector<double> desired = {0, 1, 1, 1, 1};
  const ServoPlan plan =
      PlanJointModelRequests(p, kTickS, desired, {-180, 180, kHuge}, PlanMethod::kModelBased);
  const std::vector<double> expected = {2, 1, 1, 1, 1};
  for (size_t t = 0; t < desired.size(); ++t) {
    EXPECT_NEAR(plan.request_deg[t], expected[t], 1e-9) << t;
    EXPECT_NEAR(plan.predicted_deg[t], desired[t], 1e-9) << t;
  }
  EXPECT_EQ(plan.beyond_servo_ticks, 0);
}

// A 10 deg jump at tick 5 at 2 deg a tick: M(5..9) = 2, 4, 6, 8, 10, so ticks 5..8 miss (4
// flags). Where the servo saturates the least-effort request is M + theta_0 (f(4) = 2 already).
TEST(ServoPlanTest, PaperModelSaturatedStepFlagsTheTicksItMisses) {
  const JointModelParams p{2.0, 4.0, 0, 1};
  std::vector<double> desired(12, 0.0);
  std::fill(desired.begin() + 5, desired.end(), 10.0);
  const ServoPlan plan =
      PlanJointModelRequests(p, kTickS, desired, {-180, 180, kHuge}, PlanMethod::kModelBased);
  const std::vector<double> requests = {0, 0, 0, 0, 4, 6, 8, 10, 12, 10, 10, 10};
  const std::vector<double> angles = {0, 0, 0, 0, 0, 2, 4, 6, 8, 10, 10, 10};
  for (size_t t = 0; t < desired.size(); ++t) {
    EXPECT_NEAR(plan.request_deg[t], requests[t], 1e-9) << t;
    EXPECT_NEAR(plan.predicted_deg[t], angles[t], 1e-9) << t;
    EXPECT_EQ(plan.beyond_servo[t], t >= 5 && t <= 8 ? 1 : 0) << t;
  }
  EXPECT_EQ(plan.beyond_servo_ticks, 4);
}

// No load, no friction, a ramp of 20 deg/s after l + 1 ticks at rest: the model starts on the
// desired path, so the inversion along it (w* = w_d + (w_d(k) - w_d(k-1)) / blend, then the
// P-law) keeps it there, every tick: at the ramp's start w* = 20 / blend makes w = 20 in one
// tick, then w* = 20 holds it.
TEST(ServoPlanTest, ExtendedModelFollowsASlowRampExactly) {
  const ServoModelParams p = Extended();
  std::vector<double> desired(400);
  const long rest = p.lag_ticks + 1;
  for (size_t t = 0; t < desired.size(); ++t) {
    desired[t] = 20.0 * kTickS * static_cast<double>(std::max(0L, static_cast<long>(t) - rest));
  }
  const ServoPlan plan = PlanServoRequests(p, {.kp = 10}, kTickS, desired, {-180, 180, kHuge},
                                           PlanMethod::kModelBased);
  for (size_t t = 0; t < desired.size(); ++t) {
    EXPECT_NEAR(plan.predicted_deg[t], desired[t], 1e-9) << t;
  }
  EXPECT_EQ(plan.beyond_servo_ticks, 0);
  // The plan's prediction is the model's under its requests, from rest at D(0).
  ServoModelState state = ServoRestState(p, desired[0]);
  for (size_t t = 0; t < desired.size(); ++t) {
    EXPECT_EQ(StepServoModel(p, {.kp = 10}, kTickS, state, plan.request_deg[t]),
              plan.predicted_deg[t]);
  }
}

TEST(ServoPlanTest, LimitsAreNeverViolated) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jump(-50.0, 50.0);
  std::vector<double> desired(300, 0.0);
  for (size_t t = 10; t < desired.size(); ++t) {
    desired[t] = t % 20 == 0 ? jump(rng) : desired[t - 1];
  }
  const ServoLimits limits{-30.0, 30.0, 200.0};
  const ServoDrive drive{.kp = 10, .mass_kg = 0.2, .length_m = 0.1};
  for (const PlanMethod method : {PlanMethod::kModelBased, PlanMethod::kOptimal}) {
    const ServoPlan servo =
        PlanServoRequests(Extended(0.02, 0.3), drive, kTickS, desired, limits, method);
    ExpectWithinLimits(servo, desired[0], limits, kTickS);
    EXPECT_GT(servo.beyond_servo_ticks, 0);  // +-50 deg is beyond +-30
    const ServoPlan paper =
        PlanJointModelRequests({2.0, 4.0, 1, 3}, kTickS, desired, limits, method);
    ExpectWithinLimits(paper, desired[0], limits, kTickS);
  }
}

// 0.2 kg at 0.1 m held at 30 deg: load duty g = 0.2 * 9.81 * 0.1 * sin(30 deg) = 0.0981 and a
// band of 0.05 + 0.5 g = 0.099 > g, so every error in [-0.01, 1.97] deg holds it still; the
// least-effort request is the angle itself.
TEST(ServoPlanTest, InsideTheFrictionBandTheRequestIsTheAngle) {
  const std::vector<double> desired(50, 30.0);
  const ServoPlan plan =
      PlanServoRequests(Extended(0.05, 0.5), {.kp = 10, .mass_kg = 0.2, .length_m = 0.1}, kTickS,
                        desired, {-180, 180, kHuge}, PlanMethod::kModelBased);
  for (size_t t = 0; t < desired.size(); ++t) {
    EXPECT_DOUBLE_EQ(plan.request_deg[t], 30.0) << t;
    EXPECT_DOUBLE_EQ(plan.predicted_deg[t], 30.0) << t;
  }
  EXPECT_EQ(plan.beyond_servo_ticks, 0);
}

// A 20 deg step under a request speed limit of 1 deg a tick: the tick-by-tick inversion starts
// only when the step is l + 1 ticks away; starting earlier costs less in all.
TEST(ServoPlanTest, OptimalIsNeverWorseAndAnticipatesASpeedLimit) {
  std::vector<double> desired(80, 0.0);
  std::fill(desired.begin() + 30, desired.end(), 20.0);
  const ServoLimits limits{-180, 180, 200.0};
  const ServoDrive drive{.kp = 10};
  const ServoPlan based =
      PlanServoRequests(Extended(), drive, kTickS, desired, limits, PlanMethod::kModelBased);
  const ServoPlan optimal =
      PlanServoRequests(Extended(), drive, kTickS, desired, limits, PlanMethod::kOptimal);
  ExpectWithinLimits(optimal, desired[0], limits, kTickS);
  const double based_error = SquaredError(based.predicted_deg, desired);
  const double optimal_error = SquaredError(optimal.predicted_deg, desired);
  EXPECT_LT(optimal_error, 0.9 * based_error);
  // It moves before tick 27, where R(27) first acts on the step at 30.
  EXPECT_GT(*std::max_element(optimal.request_deg.begin(), optimal.request_deg.begin() + 27), 0.5);
  // The paper's model and a plan with nothing to gain: still never worse.
  const JointModelParams paper{2.0, 4.0, 1, 3};
  const double paper_based = SquaredError(
      PlanJointModelRequests(paper, kTickS, desired, limits, PlanMethod::kModelBased).predicted_deg,
      desired);
  const double paper_optimal = SquaredError(
      PlanJointModelRequests(paper, kTickS, desired, limits, PlanMethod::kOptimal).predicted_deg,
      desired);
  EXPECT_LE(paper_optimal, paper_based);
}

// The whole-motion optimum as the batch plan found it before blocks: HorizonDescent from rest
// over every tick, from the model-based requests, as far as kOptimalMaxIterations.
std::vector<double> WholeMotionOptimum(const ServoModelParams& params, const ServoDrive& drive,
                                       const std::vector<double>& desired,
                                       const ServoLimits& limits, std::vector<double> requests) {
  const servo_plan::ExtendedStepper stepper{params, drive, kTickS};
  ServoModelState pending = stepper.Rest(desired[0]);
  stepper.Advance(pending);
  servo_plan::HorizonDescent<servo_plan::ExtendedStepper> descent;
  descent.Reserve(requests.size(), desired.size() - 1, pending);
  descent.Descend(stepper, pending, desired,
                  {limits.min_deg, limits.max_deg, limits.max_speed_deg_s * kTickS, desired[0]},
                  requests, requests.size(), {.max_iterations = kOptimalMaxIterations});
  return requests;
}

// The model's angles under `requests` from rest at D(0), as a plan's predicted_deg.
std::vector<double> FromRestAtTheStart(const ServoModelParams& params, const ServoDrive& drive,
                                       const std::vector<double>& desired,
                                       const std::vector<double>& requests) {
  ServoModelState state = ServoRestState(params, desired[0]);
  std::vector<double> angles(requests.size());
  for (size_t t = 0; t < requests.size(); ++t) {
    angles[t] = StepServoModel(params, drive, kTickS, state, requests[t]);
  }
  return angles;
}

// A sum of sines of drifting amplitude, beyond the servo at its peaks (saturating at 10 deg of
// error, 0.5 kg at 0.1 m against a 1 N m stall torque).
std::vector<double> LongMotion(size_t ticks, double slow_hz = 0.7, double fast_hz = 2.3) {
  std::vector<double> d(ticks);
  for (size_t t = 0; t < ticks; ++t) {
    const double s = static_cast<double>(t) * kTickS;
    const double drift = 0.6 + 0.4 * std::sin(2.0 * std::numbers::pi * 0.1 * s);
    d[t] = drift * (40.0 * std::sin(2.0 * std::numbers::pi * slow_hz * s) +
                    15.0 * std::sin(2.0 * std::numbers::pi * fast_hz * s));
  }
  return d;
}

// A motion of one block is that whole-motion optimum, bit for bit; longer ones, planned block
// by block, are never above the model-based plan and within 1 % of the whole-motion optimum
// (by the objective; blocks and whole measured 0.97-1.003 of each other on twelve such
// motions of 5000 ticks).
TEST(ServoPlanTest, OptimalBlocksAreNearTheWholeMotionOptimum) {
  const ServoDrive drive{.kp = 10, .mass_kg = 0.5, .length_m = 0.1};
  const ServoLimits limits{-90.0, 90.0, 400.0};
  const std::vector<double> one_block = LongMotion(kOptimalBlockTicks + kOptimalOverlapTicks);
  const ServoPlan based =
      PlanServoRequests(Extended(), drive, kTickS, one_block, limits, PlanMethod::kModelBased);
  EXPECT_EQ(PlanServoRequests(Extended(), drive, kTickS, one_block, limits, PlanMethod::kOptimal)
                .request_deg,
            WholeMotionOptimum(Extended(), drive, one_block, limits, based.request_deg));
  for (const double slow_hz : {0.3, 0.7}) {
    for (const double fast_hz : {1.7, 3.1}) {
      const std::vector<double> desired = LongMotion(4000, slow_hz, fast_hz);
      const ServoPlan model_based =
          PlanServoRequests(Extended(), drive, kTickS, desired, limits, PlanMethod::kModelBased);
      const ServoPlan optimal =
          PlanServoRequests(Extended(), drive, kTickS, desired, limits, PlanMethod::kOptimal);
      ExpectWithinLimits(optimal, desired[0], limits, kTickS);
      const std::vector<double> whole =
          WholeMotionOptimum(Extended(), drive, desired, limits, model_based.request_deg);
      const double whole_error =
          SquaredError(FromRestAtTheStart(Extended(), drive, desired, whole), desired);
      const double optimal_error = SquaredError(optimal.predicted_deg, desired);
      EXPECT_LT(optimal_error, SquaredError(model_based.predicted_deg, desired))
          << slow_hz << " " << fast_hz;
      EXPECT_LE(optimal_error, 1.01 * whole_error) << slow_hz << " " << fast_hz;
    }
  }
}

// The velocity w(k) the extended model reaches in one tick from the desired path at k - 1
// (angle D(k-1), velocity w_d(k-1)) when `request` is the one acting: stepped here by the
// model's own StepServoModel, not by the planner's inversion.
double VelocityFromThePath(const ServoModelParams& p, const ServoDrive& drive, double angle,
                           double velocity, double request) {
  ServoModelState state = ServoRestState(p, angle);
  state.velocity_deg_s = velocity;
  state.past_requests_deg.back() = request;
  StepServoModel(p, drive, kTickS, state, request);
  return state.velocity_deg_s;
}

// Against a grid of 40001 requests: on the desired path, the plan's R(t) gives the desired
// velocity at k = t + l + 1 at least as closely as the grid's best request (with a load and a
// friction band, which the inversion must step over).
TEST(ServoPlanTest, ModelBasedInvertsTheModelAlongThePath) {
  const ServoModelParams p = Extended(0.02, 0.2);
  const ServoDrive drive{.kp = 10, .mass_kg = 0.3, .length_m = 0.1};
  const std::vector<double> desired = {10, 10, 10, 10.3, 10.9, 11.4, 11.6, 11.5, 11.0, 10.8, 10.8};
  const ServoPlan plan =
      PlanServoRequests(p, drive, kTickS, desired, {-180, 180, kHuge}, PlanMethod::kModelBased);
  const auto d = [&](long k) { return desired[std::clamp<long>(k, 0, 10)]; };
  const auto w = [&](long k) { return (d(k) - d(k - 1)) / kTickS; };
  for (long t = 0; t + p.lag_ticks + 1 < 11; ++t) {
    const long k = t + p.lag_ticks + 1;
    double best_miss = std::numeric_limits<double>::infinity();
    constexpr int kPoints = 40001;
    for (int i = 0; i < kPoints; ++i) {
      const double r = d(k - 1) - 20.0 + 40.0 * i / (kPoints - 1);
      best_miss = std::min(best_miss,
                           std::abs(VelocityFromThePath(p, drive, d(k - 1), w(k - 1), r) - w(k)));
    }
    const double plan_miss =
        std::abs(VelocityFromThePath(p, drive, d(k - 1), w(k - 1), plan.request_deg[t]) - w(k));
    EXPECT_LE(plan_miss, best_miss + 1e-9) << t;
  }
}

TEST(ServoPlanTest, BadInputThrows) {
  const std::vector<double> desired = {0, 1, 2};
  const ServoDrive drive{.kp = 10};
  const auto plan = [&](ServoModelParams p, ServoDrive d, double tick, std::vector<double> des,
                        ServoLimits lim) {
    return PlanServoRequests(p, d, tick, des, lim, PlanMethod::kModelBased);
  };
  const ServoLimits ok{-180, 180, 100};
  ServoModelParams bad = Extended();
  bad.velocity_lag_s = 0.0;
  EXPECT_THROW(plan(bad, drive, kTickS, desired, ok), std::invalid_argument);
  EXPECT_THROW(plan(Extended(), {.kp = 0}, kTickS, desired, ok), std::invalid_argument);
  EXPECT_THROW(plan(Extended(), drive, 0.0, desired, ok), std::invalid_argument);
  EXPECT_THROW(plan(Extended(), drive, kTickS, {}, ok), std::invalid_argument);
  EXPECT_THROW(plan(Extended(), drive, kTickS, {0, NAN}, ok), std::invalid_argument);
  EXPECT_THROW(plan(Extended(), drive, kTickS, desired, {10, 10, 100}), std::invalid_argument);
  EXPECT_THROW(plan(Extended(), drive, kTickS, desired, {-10, 10, 0}), std::invalid_argument);
  EXPECT_THROW(plan(Extended(), drive, kTickS, {20, 0}, {-10, 10, 100}), std::invalid_argument);
  EXPECT_THROW(PlanJointModelRequests({2.0, 0.0, 0, 1}, kTickS, desired, ok, PlanMethod::kOptimal),
               std::invalid_argument);
}

// Numbers each in its own range that together would make a NaN or an infinity somewhere in the
// plan (a load of 1e300 duty, a slope of 1e324, a tick of 5e-324 s, a desired angle of 1e308)
// are refused, naming what is wrong; just inside each bound the plan is finite.
TEST(ServoPlanTest, WhatWouldMakeANaNIsRefusedAndJustInsideIsFinite) {
  const std::vector<double> desired = {0, 5, 10, 5, 0};
  const ServoLimits limits{-180, 180, 1000};
  const auto problem = [&](const ServoModelParams& p, const ServoDrive& d, double tick,
                           const std::vector<double>& des) -> std::string {
    for (const PlanMethod method : {PlanMethod::kModelBased, PlanMethod::kOptimal}) {
      try {
        const ServoPlan plan = PlanServoRequests(p, d, tick, des, limits, method);
        for (size_t t = 0; t < des.size(); ++t) {
          EXPECT_TRUE(std::isfinite(plan.request_deg[t]) && std::isfinite(plan.predicted_deg[t]));
        }
      } catch (const std::invalid_argument& e) {
        return e.what();
      }
    }
    return "";
  };
  ServoModelParams weak = Extended();
  weak.stall_torque_nm = 5e-324;
  EXPECT_NE(problem(weak, {.kp = 10, .mass_kg = 0.1, .length_m = 0.1}, kTickS, desired)
                .find("mass_kg x 9.81 x length_m / stall_torque_nm"),
            std::string::npos);
  // A load of 1000 times the stall torque is the most: 0.1 x 9.81 x 1 / 0.000981.
  weak.stall_torque_nm = 0.1 * 9.81 * 1.0 / 1000.0 * (1 + 1e-12);
  EXPECT_EQ(problem(weak, {.kp = 10, .mass_kg = 0.1, .length_m = 1.0}, kTickS, desired), "");
  // A load beyond the drive's declared range is refused by it before any product is formed.
  EXPECT_NE(problem(Extended(), {.kp = 10, .mass_kg = 1e300, .length_m = 1e300}, kTickS, desired)
                .find("mass_kg must be in [0, 1000] kg"),
            std::string::npos);
  EXPECT_EQ(problem(Extended(), {.kp = 1e6, .mass_kg = 1000, .length_m = 10}, kTickS, desired)
                .find("must be in"),
            std::string::npos);
  EXPECT_NE(problem(Extended(), {.kp = 0}, kTickS, desired).find("kp must be in (0, 1000000]"),
            std::string::npos);
  EXPECT_NE(
      problem(Extended(), {.kp = 10}, 5e-324, desired).find("tick_s must be in [1e-06, 10] s"),
      std::string::npos);
  EXPECT_NE(problem(Extended(), {.kp = 10}, kTickS, {0, 1e308})
                .find("desired angle 1 must be in [-100000, 100000] deg"),
            std::string::npos);
  EXPECT_EQ(problem(Extended(), {.kp = 10}, kTickS, {0, kMaxPlanAngleDeg}), "");
  ServoModelParams sluggish = Extended();
  sluggish.velocity_lag_s = 1e300;
  EXPECT_NE(problem(sluggish, {.kp = 10}, kTickS, desired).find("velocity_lag_s must be in (0, "),
            std::string::npos);
  const auto paper_problem = [&](const JointModelParams& p) -> std::string {
    try {
      PlanJointModelRequests(p, kTickS, desired, limits, PlanMethod::kOptimal);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(paper_problem({2.0, 5e-324, 0, 1}).find("v_max_deg_per_tick / theta0_deg"),
            std::string::npos);
  EXPECT_EQ(paper_problem({2.0, 2e-9, 0, 1}), "");
}

}  // namespace
}  // namespace leglab
