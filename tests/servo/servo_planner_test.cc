#include "leglab/servo/servo_planner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <numbers>
#include <random>
#include <span>
#include <stdexcept>
#include <vector>

#include "horizon_descent.h"   // the receding horizon's optimiser (internal)
#include "servo_model_tick.h"  // the extended model's coefficients (internal)
#include "servo_plan_steps.h"  // the receding horizon's error and gradient (internal)

// Every allocation of this test program counted, to show that a planner's ticks make none.
namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
// The replaced operator new allocates with malloc, so free is its match (GCC cannot tell).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t /*size*/) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace leglab {
namespace {

constexpr double kTickS = 0.005;

// Saturating at 20 deg of error at kp 100, a load of up to 0.39 duty, friction that grows
// with it, and two ticks of lag: every branch of the extended model is taken.
ServoModelParams Extended() {
  return {.gain_per_deg_kp = 5e-4,
          .v_max_deg_s = 400.0,
          .stall_torque_nm = 0.5,
          .friction_duty = 0.03,
          .friction_load_ratio = 0.2,
          .velocity_lag_s = 0.02,
          .lag_ticks = 2};
}
constexpr ServoDrive kDrive{.kp = 100.0, .mass_kg = 0.2, .length_m = 0.1};

JointModelParams Paper() {
  return {.v_max_deg_per_tick = 2.0, .theta0_deg = 8.0, .lag_ticks = 3, .accel_ticks = 4};
}

// Within +-60 deg, the request at most 300 deg/s: slower than the servo, so the speed limit
// binds on the step.
constexpr ServoLimits kLimits{.min_deg = -60.0, .max_deg = 60.0, .max_speed_deg_s = 300.0};

// A 1 Hz sine of 40 deg, a 30 deg step at tick 300, then a slow ramp: the plan saturates, meets
// the speed limit and follows exactly in turn.
std::vector<double> Desired() {
  std::vector<double> d(600);
  for (size_t t = 0; t < d.size(); ++t) {
    const double s = static_cast<double>(t) * kTickS;
    d[t] = t < 300   ? 40.0 * std::sin(2.0 * std::numbers::pi * s)
           : t < 450 ? 30.0
                     : 30.0 - 0.1 * static_cast<double>(t - 450);
  }
  return d;
}

// D(t..t+count-1), cut at the trajectory's end.
std::span<const double> Window(const std::vector<double>& d, size_t t, size_t count) {
  return std::span<const double>(d).subspan(t, std::min(count, d.size() - t));
}

// The planner fed what the batch plan predicts: its requests.
std::vector<double> OnlineRequests(ServoPlanner& planner, const std::vector<double>& desired,
                                   const std::vector<double>& measured, size_t window) {
  planner.Reset(desired[0]);
  std::vector<double> requests(desired.size());
  for (size_t t = 0; t < desired.size(); ++t) {
    requests[t] = planner.Request(Window(desired, t, window), measured[t]);
  }
  return requests;
}

TEST(ServoPlanner, ModelBasedOnlineIsTheBatchPlanBitForBit) {
  const std::vector<double> d = Desired();
  const ServoPlan batch =
      PlanServoRequests(Extended(), kDrive, kTickS, d, kLimits, PlanMethod::kModelBased);
  ASSERT_GT(batch.beyond_servo_ticks, 0);  // the step saturates: the clamps are exercised
  ServoPlanner planner(Extended(), kDrive, kTickS, kLimits);
  EXPECT_EQ(planner.HorizonTicks(), 3);
  EXPECT_EQ(planner.PreviewTicks(), 3);
  for (const size_t window : {size_t{4}, size_t{50}}) {  // the horizon, and more than it needs
    const std::vector<double> online = OnlineRequests(planner, d, batch.predicted_deg, window);
    for (size_t t = 0; t < d.size(); ++t) ASSERT_EQ(online[t], batch.request_deg[t]) << t;
  }
}

TEST(ServoPlanner, ModelBasedOnlineIsTheBatchPlanForThePapersModel) {
  const std::vector<double> d = Desired();
  const ServoPlan batch =
      PlanJointModelRequests(Paper(), kTickS, d, kLimits, PlanMethod::kModelBased);
  ASSERT_GT(batch.beyond_servo_ticks, 0);
  ServoPlanner planner(Paper(), kTickS, kLimits);
  EXPECT_EQ(planner.HorizonTicks(), 4);
  const std::vector<double> online = OnlineRequests(planner, d, batch.predicted_deg, 5);
  for (size_t t = 0; t < d.size(); ++t) ASSERT_EQ(online[t], batch.request_deg[t]) << t;
}

// The horizon's gradient against central differences of its error, for both models, at random
// plans that saturate some ticks and not others.
template <class Stepper>
void ExpectGradientIsFiniteDifferences(const Stepper& stepper, const typename Stepper::State& rest,
                                       std::mt19937& random) {
  const int lag = stepper.Lag();
  const int preview = 40;
  std::vector<double> desired(static_cast<size_t>(preview) + 1);
  std::uniform_real_distribution<double> angle(-30.0, 30.0);
  for (double& x : desired) x = angle(random);
  std::vector<double> plan(static_cast<size_t>(preview - lag));
  for (double& x : plan) x = angle(random);
  typename Stepper::State pending = rest;
  for (int i = 0; i < 5; ++i) {  // some history
    Stepper::Push(pending, angle(random));
    stepper.Advance(pending);
  }
  typename Stepper::State scratch = pending;
  std::vector<double> angles(desired.size());
  servo_plan::HorizonError(stepper, pending, scratch, plan, desired, angles);
  std::vector<double> gradient(plan.size());
  servo_plan::HorizonGradient(stepper, pending, plan, desired, angles, gradient);
  const double h = 1e-6;
  for (size_t i = 0; i < plan.size(); ++i) {
    std::vector<double> up = plan;
    std::vector<double> down = plan;
    up[i] += h;
    down[i] -= h;
    const double numeric =
        (servo_plan::HorizonError(stepper, pending, scratch, up, desired, {}) -
         servo_plan::HorizonError(stepper, pending, scratch, down, desired, {})) /
        (2 * h);
    EXPECT_NEAR(gradient[i], numeric, 1e-5 * std::max(1.0, std::abs(numeric))) << "request " << i;
  }
}

TEST(ServoPlanner, HorizonGradientIsTheFiniteDifferenceOfItsError) {
  std::mt19937 random(7);
  const ServoModelParams extended = Extended();
  const JointModelParams paper = Paper();
  for (int trial = 0; trial < 5; ++trial) {
    ExpectGradientIsFiniteDifferences(servo_plan::ExtendedStepper{extended, kDrive, kTickS},
                                      ServoRestState(extended, 10.0), random);
    ExpectGradientIsFiniteDifferences(servo_plan::PaperStepper{paper}, RestState(paper, 10.0),
                                      random);
  }
}

// A servo that is the model itself, held still for ticks [hold_from, hold_until) (its angle
// kept, its velocity 0), driven by `request` each tick: returns its angles.
template <class RequestFn>
std::vector<double> HeldServo(const std::vector<double>& desired, size_t hold_from,
                              size_t hold_until, RequestFn&& request) {
  const ServoModelParams params = Extended();
  ServoModelState servo = ServoRestState(params, desired[0]);
  std::vector<double> angles(desired.size());
  double held = 0.0;
  for (size_t t = 0; t < desired.size(); ++t) {
    angles[t] = AdvanceServoModel(params, kDrive, kTickS, servo);
    if (t == hold_from) held = servo.angle_deg;
    if (t >= hold_from && t < hold_until) {
      servo.angle_deg = angles[t] = held;
      servo.velocity_deg_s = 0.0;
    }
    PushServoModelRequest(servo, request(t, angles[t]));
  }
  return angles;
}

// The planner on a held servo, feeding it the measured angles: its requests and how many
// ticks re-anchored its model.
struct HeldRun {
  std::vector<double> angles;
  std::vector<double> requests;
  int reanchored = 0;
};
HeldRun RunHeld(ServoPlanner& planner, const std::vector<double>& d, size_t from, size_t until) {
  HeldRun run;
  planner.Reset(d[0]);
  run.angles = HeldServo(d, from, until, [&](size_t t, double measured) {
    run.requests.push_back(planner.Request(Window(d, t, 4), measured));
    run.reanchored += planner.Reanchored() ? 1 : 0;
    return run.requests.back();
  });
  return run;
}

TEST(ServoPlanner, AHeldServoReanchorsTheModelAndKeepsTheExtendedModelsPlan) {
  const std::vector<double> d = Desired();
  const ServoPlan batch =
      PlanServoRequests(Extended(), kDrive, kTickS, d, kLimits, PlanMethod::kModelBased);
  // Held for 0.25 s from the sine's falling zero crossing to its trough.
  const size_t from = 100;
  const size_t until = 150;
  const std::vector<double> open_loop =
      HeldServo(d, from, until, [&](size_t t, double) { return batch.request_deg[t]; });

  // The requests stay the batch plan's: the servo's P-law brings it back.
  ServoPlanner planner(Extended(), kDrive, kTickS, kLimits);
  const HeldRun kept = RunHeld(planner, d, from, until);
  EXPECT_GT(kept.reanchored, 0);
  EXPECT_EQ(kept.requests, batch.request_deg);
  EXPECT_EQ(kept.angles, open_loop);

  // What the planner's model predicts follows the measurements while held.
  EXPECT_NEAR(planner.PredictedDeg(), kept.angles.back(), 2.0);
}

// A loop that misses ticks: the servo holds its last request through them. Told so by Hold,
// the planner's model is the model driven by what the servo really got, its requests keep the
// speed limit from the held one, and model_based's are the batch plan's again once the speed
// limit has let them catch up (30 ticks covers the 30 deg step at 1.5 deg a tick).
TEST(ServoPlanner, AHeldTickAdvancesTheModelByTheRequestTheServoKept) {
  const std::vector<double> d = Desired();
  const ServoPlan batch =
      PlanServoRequests(Extended(), kDrive, kTickS, d, kLimits, PlanMethod::kModelBased);
  const std::vector<size_t> missed{0, 40, 41, 42, 301, 302};
  const auto caught_up = [&](size_t t) {
    return std::none_of(missed.begin(), missed.end(),
                        [&](size_t m) { return t > m && t <= m + 30; });
  };
  for (const PlanMethod method : {PlanMethod::kModelBased, PlanMethod::kOptimal}) {
    ServoPlannerOptions options;
    options.method = method;
    ServoPlanner planner(Extended(), kDrive, kTickS, kLimits, options);
    planner.Reset(d[0]);
    // The servo, simulated independently: the model stepped with the requests it received.
    ServoModelState servo = ServoRestState(Extended(), d[0]);
    double sent = d[0];
    for (size_t t = 0; t < d.size(); ++t) {
      const double measured = AdvanceServoModel(Extended(), kDrive, kTickS, servo);
      ASSERT_EQ(planner.ExpectedDeg(), measured) << t;
      if (std::find(missed.begin(), missed.end(), t) != missed.end()) {
        planner.Hold(Window(d, t, 100));
      } else {
        const double r = planner.Request(Window(d, t, 100), measured);
        ASSERT_LE(std::abs(r - sent), kLimits.max_speed_deg_s * kTickS + 1e-12) << t;
        if (method == PlanMethod::kModelBased && caught_up(t)) {
          ASSERT_EQ(r, batch.request_deg[t]) << t;
        }
        sent = r;
      }
      PushServoModelRequest(servo, sent);
    }
    EXPECT_EQ(planner.Ticks(), static_cast<long>(d.size()));
  }
}

TEST(ServoPlanner, TicksMakeNoAllocation) {
  const std::vector<double> d = Desired();
  for (const int hold : {-1, 0, 20}) {
    ServoPlannerOptions options;
    options.method = hold < 0 ? PlanMethod::kModelBased : PlanMethod::kOptimal;
    options.hold_ticks = std::max(hold, 0);
    options.optimal_iterations_per_tick = 20;
    const PlanMethod method = options.method;
    ServoPlanner extended(Extended(), kDrive, kTickS, kLimits, options);
    ServoPlanner paper(Paper(), kTickS, kLimits, options);
    for (ServoPlanner* planner : {&extended, &paper}) {
      const long before = g_allocations.load();
      planner->Reset(d[0]);
      for (size_t t = 0; t < d.size(); ++t) {
        // Pushed 5 deg off the prediction every 50th tick: the re-anchoring path too.
        const double measured = planner->ExpectedDeg() + (t % 50 == 49 ? 5.0 : 0.0);
        if (t % 70 == 69) {
          planner->Hold(Window(d, t, 100));  // a missed tick
        } else {
          planner->Request(Window(d, t, 100), measured);
        }
      }
      EXPECT_EQ(g_allocations.load() - before, 0) << static_cast<int>(method);
    }
  }
}

// Online optimal on the model itself: within the limits, and below the model-based plan's
// error (its first guess) and near the batch optimum, through the speed-limited step where
// line searches fail.
TEST(ServoPlanner, OptimalOnlineImprovesOnModelBasedWithinTheLimits) {
  const std::vector<double> d = Desired();
  ServoPlannerOptions options;
  options.method = PlanMethod::kOptimal;
  options.budget_s = 0.0;  // the iteration cap alone: the same requests on every machine
  ServoPlanner planner(Extended(), kDrive, kTickS, kLimits, options);
  EXPECT_EQ(planner.PreviewTicks(), 2 + 18 + kOptimalWindowTicks);
  std::vector<double> predicted(d.size());
  double previous = d[0];
  planner.Reset(d[0]);
  for (size_t t = 0; t < d.size(); ++t) {
    predicted[t] = planner.ExpectedDeg();
    const double r = planner.Request(Window(d, t, 64), predicted[t]);
    ASSERT_LE(std::abs(r - previous), kLimits.max_speed_deg_s * kTickS + 1e-12) << t;
    ASSERT_GE(r, kLimits.min_deg);
    ASSERT_LE(r, kLimits.max_deg);
    previous = r;
  }
  const auto mae = [&](const std::vector<double>& angles) {
    double sum = 0.0;
    for (size_t t = 0; t < d.size(); ++t) sum += std::abs(angles[t] - d[t]);
    return sum / static_cast<double>(d.size());
  };
  const double based =
      mae(PlanServoRequests(Extended(), kDrive, kTickS, d, kLimits, PlanMethod::kModelBased)
              .predicted_deg);
  const double batch =
      mae(PlanServoRequests(Extended(), kDrive, kTickS, d, kLimits, PlanMethod::kOptimal)
              .predicted_deg);
  EXPECT_LT(mae(predicted), based);
  EXPECT_LT(mae(predicted), batch + 0.1);
}

// Optimal's plan keeps model_based's requests on the preview's last handover_ticks ticks (by
// default 2 (l + 1) and three velocity lags, 6 + 12 here; 8 + a = 12 for the paper's model):
// with a preview of at most l + handover no request is left to descend, and a budget spent
// before the first iteration sends the plan it starts from. Both are model_based's requests,
// bit for bit, for both rungs (with the batch plan's predictions as measurements).
TEST(ServoPlanner, OptimalWithNoRoomOrNoTimeToDescendIsModelBased) {
  const std::vector<double> d = Desired();
  struct Case {
    bool paper;
    int preview_ticks;
    double budget_s;
  };
  for (const Case c : {Case{false, 3, 0.0}, Case{false, 2 + 18, 0.0}, Case{false, 62, 1e-12},
                       Case{true, 4, 0.0}, Case{true, 3 + 12, 0.0}, Case{true, 62, 1e-12}}) {
    ServoPlannerOptions options;
    options.method = PlanMethod::kOptimal;
    options.preview_ticks = c.preview_ticks;
    options.budget_s = c.budget_s;
    const auto window = static_cast<size_t>(c.preview_ticks) + 1;
    const ServoPlan batch =
        c.paper
            ? PlanJointModelRequests(Paper(), kTickS, d, kLimits, PlanMethod::kModelBased)
            : PlanServoRequests(Extended(), kDrive, kTickS, d, kLimits, PlanMethod::kModelBased);
    ServoPlanner online = c.paper ? ServoPlanner(Paper(), kTickS, kLimits, options)
                                  : ServoPlanner(Extended(), kDrive, kTickS, kLimits, options);
    const std::vector<double> requests = OnlineRequests(online, d, batch.predicted_deg, window);
    for (size_t t = 0; t < d.size(); ++t) {
      ASSERT_EQ(requests[t], batch.request_deg[t]) << c.paper << " " << c.preview_ticks << " " << t;
    }
  }
  // One request more to descend, and the plan moves off model_based's.
  ServoPlannerOptions options;
  options.method = PlanMethod::kOptimal;
  options.preview_ticks = 2 + 18 + 1;
  options.budget_s = 0.0;
  const ServoPlan batch =
      PlanServoRequests(Extended(), kDrive, kTickS, d, kLimits, PlanMethod::kModelBased);
  ServoPlanner online(Extended(), kDrive, kTickS, kLimits, options);
  EXPECT_NE(OnlineRequests(online, d, batch.predicted_deg, 22), batch.request_deg);
  // An explicit hand-over: 2 (l + 1) alone leaves room at a preview of 9.
  options.preview_ticks = 9;
  options.handover_ticks = 6;
  ServoPlanner short_handover(Extended(), kDrive, kTickS, kLimits, options);
  EXPECT_NE(OnlineRequests(short_handover, d, batch.predicted_deg, 10), batch.request_deg);
  options.preview_ticks = 8;
  ServoPlanner no_room(Extended(), kDrive, kTickS, kLimits, options);
  EXPECT_EQ(OnlineRequests(no_room, d, batch.predicted_deg, 9), batch.request_deg);
}

// With no hand-over and no hold every request of the plan descends: shifting it one tick on
// takes its last request from model_based's plan (it read past the plan's end before), and the
// planner runs, held ticks and re-anchors included, within the limits. For both rungs.
TEST(ServoPlanner, OptimalWithEveryRequestFreeStaysWithinThePlan) {
  const std::vector<double> d = Desired();
  for (const bool paper : {false, true}) {
    for (const int preview : {paper ? 4 : 3, 20}) {
      ServoPlannerOptions options;
      options.method = PlanMethod::kOptimal;
      options.preview_ticks = preview;
      options.handover_ticks = 0;
      options.budget_s = 0.0;
      options.optimal_iterations_per_tick = 5;
      ServoPlanner planner = paper ? ServoPlanner(Paper(), kTickS, kLimits, options)
                                   : ServoPlanner(Extended(), kDrive, kTickS, kLimits, options);
      planner.Reset(d[0]);
      double previous = d[0];
      for (size_t t = 0; t < d.size(); ++t) {
        const std::span<const double> window = Window(d, t, static_cast<size_t>(preview) + 1);
        if (t % 40 == 39) {
          planner.Hold(window);
          continue;
        }
        const double measured = planner.ExpectedDeg() + (t % 50 == 49 ? 5.0 : 0.0);
        const double r = planner.Request(window, measured);
        ASSERT_TRUE(std::isfinite(r)) << paper << " " << preview << " " << t;
        ASSERT_LE(std::abs(r - previous), kLimits.max_speed_deg_s * kTickS + 1e-12) << t;
        ASSERT_GE(r, kLimits.min_deg);
        ASSERT_LE(r, kLimits.max_deg);
        previous = r;
      }
    }
  }
}

// HorizonDescent from random states and plans: never above the error it starts from (after the
// projection), within the bounds, its held requests those given (re-projected), and a deadline
// already passed takes no iteration.
TEST(ServoPlanner, HorizonDescentOnlyLowersTheErrorAndHoldsItsTail) {
  const ServoModelParams params = Extended();
  const servo_plan::ExtendedStepper stepper{params, kDrive, kTickS};
  std::mt19937 random(7);
  std::uniform_real_distribution<double> angle(-50.0, 50.0);
  constexpr size_t kPreview = 40;
  const size_t decisions = kPreview - static_cast<size_t>(params.lag_ticks);
  servo_plan::HorizonDescent<servo_plan::ExtendedStepper> descent;
  ServoModelState pending = stepper.Rest(0.0);
  descent.Reserve(decisions, kPreview, pending);
  const double step = kLimits.max_speed_deg_s * kTickS;
  for (int trial = 0; trial < 50; ++trial) {
    pending = stepper.Rest(angle(random));
    pending.velocity_deg_s = 10.0 * angle(random);
    for (double& r : pending.past_requests_deg) r = angle(random);
    stepper.Advance(pending);
    std::vector<double> desired(kPreview + 1);
    for (double& a : desired) a = angle(random);
    std::vector<double> plan(decisions);
    for (double& r : plan) r = angle(random);
    const servo_plan::RequestBounds bounds{kLimits.min_deg, kLimits.max_deg, step,
                                           pending.past_requests_deg[0]};
    const size_t free = decisions / 2;
    const std::vector<double> original = plan;
    std::vector<double> start = plan;
    servo_plan::ProjectRequests(bounds, start);
    ServoModelState scratch = pending;
    const double before = servo_plan::HorizonError(stepper, pending, scratch, start, desired, {});
    std::vector<double> spent = plan;
    const servo_plan::DescentResult none =
        descent.Descend(stepper, pending, desired, bounds, spent, free,
                        {.max_iterations = 100, .deadline = std::chrono::steady_clock::now()});
    EXPECT_EQ(none.iterations, 0);
    EXPECT_EQ(none.error, before);
    EXPECT_EQ(spent, start);
    const servo_plan::DescentResult result =
        descent.Descend(stepper, pending, desired, bounds, plan, free, {.max_iterations = 100});
    EXPECT_LE(result.error, before) << trial;
    EXPECT_EQ(result.error, servo_plan::HorizonError(stepper, pending, scratch, plan, desired, {}));
    double previous = bounds.previous_deg;
    for (size_t i = 0; i < plan.size(); ++i) {
      ASSERT_LE(std::abs(plan[i] - previous), step + 1e-12) << trial << " " << i;
      ASSERT_GE(plan[i], kLimits.min_deg);
      ASSERT_LE(plan[i], kLimits.max_deg);
      previous = plan[i];
    }
    // The held requests: those given, clamped from the last free one as ProjectRequests does.
    std::vector<double> given = plan;
    std::copy(original.begin() + static_cast<long>(free), original.end(),
              given.begin() + static_cast<long>(free));
    servo_plan::ProjectRequests(bounds, given);
    EXPECT_EQ(plan, given) << trial;
  }
}

// A descent that stalls is at a stationary point of the constrained problem: no feasible change
// of one increment R(i) - R(i-1) (which moves R(i..) together, as a ramp at the speed limit must)
// lowers the error beyond second order, by one-sided differences of the error itself. The model
// is made smooth (no friction band; steps small enough that the duty never saturates,
// asserted), and the desired angles step faster than the request's speed limit, so that the
// plan holds ramps at the limit whose requests pull different ways: where a descent in the
// requests alone stalls.
TEST(ServoPlanner, AStalledHorizonDescentIsStationaryInTheIncrements) {
  ServoModelParams params = Extended();
  params.friction_duty = 0.0;
  params.friction_load_ratio = 0.0;
  const servo_plan::ExtendedStepper stepper{params, kDrive, kTickS};
  const servo_tick::Coefficients c = servo_tick::CoefficientsOf(params, kDrive);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> jump(-12.0, 12.0);
  constexpr size_t kPreview = 60;
  const size_t decisions = kPreview - static_cast<size_t>(params.lag_ticks);
  servo_plan::HorizonDescent<servo_plan::ExtendedStepper> descent;
  ServoModelState pending = stepper.Rest(0.0);
  descent.Reserve(decisions, kPreview, pending);
  const double step = kLimits.max_speed_deg_s * kTickS;
  const servo_plan::RequestBounds bounds{kLimits.min_deg, kLimits.max_deg, step, 0.0};
  int ramps = 0;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> desired(kPreview + 1, 0.0);
    double level = 0.0;
    for (size_t j = 5; j < desired.size(); ++j) {
      if (j % 15 == 5) level += jump(random);
      desired[j] = level;
    }
    std::vector<double> plan(decisions, 0.0);
    descent.ForgetMemory();
    servo_plan::DescentResult result;
    for (int round = 0; round < 50 && !result.stalled; ++round) {
      result = descent.Descend(stepper, pending, desired, bounds, plan, decisions,
                               {.max_iterations = 1000});
    }
    ASSERT_TRUE(result.stalled) << trial;
    ServoModelState scratch = pending;
    std::vector<double> angles(desired.size());
    servo_plan::HorizonError(stepper, pending, scratch, plan, desired, angles);
    const auto lag = static_cast<size_t>(params.lag_ticks);
    for (size_t i = 0; i < plan.size(); ++i) {  // R(i)'s duty is against M(i + l)
      ASSERT_LT(std::abs(c.duty_per_deg * (plan[i] - angles[i + lag])), 1.0) << trial << " " << i;
    }
    const double e = 1e-4;
    for (size_t i = 0; i < plan.size(); ++i) {
      const double increment = plan[i] - (i == 0 ? bounds.previous_deg : plan[i - 1]);
      if (std::abs(increment) > step - 1e-6) ++ramps;
      for (const double sign : {-1.0, 1.0}) {
        if (std::abs(increment + sign * e) > step) continue;  // infeasible: the limit holds it
        std::vector<double> moved = plan;
        for (size_t k = i; k < moved.size(); ++k) moved[k] += sign * e;
        const double changed =
            servo_plan::HorizonError(stepper, pending, scratch, moved, desired, {});
        EXPECT_GT(changed, result.error - 1e-6)
            << trial << " " << i << " " << sign << ": slope " << (changed - result.error) / e;
      }
    }
  }
  EXPECT_GT(ramps, 20);  // the speed limit binds
}

TEST(ServoPlanner, ARequestBeforeAnyResetStartsAtItsWindow) {
  const std::vector<double> d = Desired();
  const ServoPlan batch =
      PlanServoRequests(Extended(), kDrive, kTickS, d, kLimits, PlanMethod::kModelBased);
  ServoPlanner planner(Extended(), kDrive, kTickS, kLimits);
  EXPECT_EQ(planner.Request(Window(d, 0, 4), batch.predicted_deg[0]), batch.request_deg[0]);
  EXPECT_EQ(planner.Ticks(), 1);
}

TEST(ServoPlanner, BadInputThrowsAndLeavesThePlannerAsItWas) {
  ServoPlanner planner(Extended(), kDrive, kTickS, kLimits);
  planner.Reset(0.0);
  const double expected = planner.ExpectedDeg();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> good{0.0, 1.0, 2.0, 3.0};
  const std::vector<double> bad{0.0, 1.0, nan, 3.0};
  EXPECT_THROW(planner.Request({}, 0.0), std::invalid_argument);
  EXPECT_THROW(planner.Request(bad, 0.0), std::invalid_argument);
  EXPECT_THROW(planner.Request(good, nan), std::invalid_argument);
  EXPECT_THROW(planner.Reset(std::numeric_limits<double>::infinity()), std::invalid_argument);
  EXPECT_THROW(planner.Reset(kLimits.max_deg + 1.0), std::invalid_argument);
  EXPECT_EQ(planner.Ticks(), 0);
  EXPECT_EQ(planner.ExpectedDeg(), expected);
  ServoPlanner fresh(Extended(), kDrive, kTickS, kLimits);
  fresh.Reset(0.0);
  EXPECT_EQ(planner.Request(good, expected), fresh.Request(good, fresh.ExpectedDeg()));
  ServoModelParams broken = Extended();
  broken.velocity_lag_s = 0.0;
  EXPECT_THROW(ServoPlanner(broken, kDrive, kTickS, kLimits), std::invalid_argument);
  EXPECT_THROW(ServoPlanner(Extended(), {.kp = 0.0}, kTickS, kLimits), std::invalid_argument);
  EXPECT_THROW(ServoPlanner(Extended(), kDrive, 0.0, kLimits), std::invalid_argument);
  EXPECT_THROW(ServoPlanner(Paper(), kTickS, {.min_deg = 1, .max_deg = 0, .max_speed_deg_s = 1}),
               std::invalid_argument);
  ServoPlannerOptions options;
  options.method = PlanMethod::kOptimal;
  options.preview_ticks = 3;  // not beyond the paper model's lag of 3
  EXPECT_THROW(ServoPlanner(Paper(), kTickS, kLimits, options), std::invalid_argument);
  options.preview_ticks = -1;
  options.reanchor_deg = 0.0;
  EXPECT_THROW(ServoPlanner(Paper(), kTickS, kLimits, options), std::invalid_argument);
  ServoModelParams long_lag = Extended();
  long_lag.lag_ticks = kMaxServoLagTicks + 1;
  EXPECT_THROW(ServoPlanner(long_lag, kDrive, kTickS, kLimits), std::invalid_argument);
}

}  // namespace
}  // namespace leglab
