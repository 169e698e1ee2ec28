#pragma once

// The pieces the batch plan (servo_plan.cc) and the online planner (servo_planner.cc) share, so
// that one tick of either is the same arithmetic: the two models as the planners step them, the
// inversion of a model at a tick, and the extended model's inversion along the desired path.
// Internal to leglab::servo.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>

#include "leglab/model/joint_model.h"
#include "leglab/servo/servo_model.h"
#include "servo_model_tick.h"

namespace leglab::servo_plan {

// The extended model as the planners step it. A "pending" state has been advanced to M(t) but
// does not yet hold R(t): Push(R(t)) then Advance() gives M(t+1); Step is the two in the
// other order.
struct ExtendedStepper {
  using State = ServoModelState;
  const ServoModelParams& params;
  const ServoDrive& drive;
  double tick_s;

  int Lag() const { return params.lag_ticks; }
  State Rest(double angle_deg) const { return ServoRestState(params, angle_deg); }
  double Advance(State& state) const { return AdvanceServoModel(params, drive, tick_s, state); }
  static void Push(State& state, double request_deg) { PushServoModelRequest(state, request_deg); }
  double Step(State& state, double request_deg) const {
    return StepServoModel(params, drive, tick_s, state, request_deg);
  }
};

// The paper's model (eq. 3) as the planners step it.
struct PaperStepper {
  using State = JointModelState;
  const JointModelParams& params;

  int Lag() const { return params.lag_ticks; }
  State Rest(double angle_deg) const { return RestState(params, angle_deg); }
  double Advance(State& state) const { return AdvanceJointModel(params, state); }
  static void Push(State& state, double request_deg) { PushJointModelRequest(state, request_deg); }
  double Step(State& state, double request_deg) const {
    return StepJointModel(params, state, request_deg);
  }
};

// The least r in [lo, hi] with reach(r) >= value, to the resolution of a double (hi if none):
// reach is non-decreasing.
template <class Reach>
double FirstAtLeast(const Reach& reach, double lo, double hi, double value) {
  if (reach(lo) >= value) return lo;
  for (double mid = lo + (hi - lo) / 2; mid > lo && mid < hi; mid = lo + (hi - lo) / 2) {
    (reach(mid) >= value ? hi : lo) = mid;
  }
  return hi;
}

// The greatest r in [lo, hi] with reach(r) <= value (lo if none).
template <class Reach>
double LastAtMost(const Reach& reach, double lo, double hi, double value) {
  if (reach(hi) <= value) return hi;
  for (double mid = lo + (hi - lo) / 2; mid > lo && mid < hi; mid = lo + (hi - lo) / 2) {
    (reach(mid) <= value ? lo : hi) = mid;
  }
  return lo;
}

struct Choice {
  double request_deg;
  double reached_deg;
};

// The least-effort request in [lo, hi] whose reached angle is nearest `target`: of the
// interval of requests that reach the best angle, the one nearest `acting_deg`.
template <class Reach>
Choice ChooseRequest(const Reach& reach, double lo, double hi, double target, double acting_deg) {
  const double at_lo = reach(lo);
  const double at_hi = reach(hi);
  double first = lo;
  double last = hi;
  if (target <= at_lo) {
    last = LastAtMost(reach, lo, hi, at_lo);
  } else if (target >= at_hi) {
    first = FirstAtLeast(reach, lo, hi, at_hi);
  } else {
    first = FirstAtLeast(reach, lo, hi, target);
    last = LastAtMost(reach, first, hi, target);
  }
  const double request = std::clamp(acting_deg, first, last);
  return {request, reach(request)};
}

// The model-based inversion at tick t: from the `pending` state (M(t), requests up to
// R(t-1), the last of them `previous`), the request R(t) in [lo, hi] that brings M(t+l+1)
// nearest `target` (ChooseRequest, the least-effort one nearest M(t+l)). `scratch` is a state
// of the same size (no allocation).
template <class Stepper>
Choice InvertAtPending(const Stepper& stepper, const typename Stepper::State& pending,
                       typename Stepper::State& scratch, double previous, double lo, double hi,
                       double target) {
  const int lag = stepper.Lag();
  // M(t+l+1) under R(t) = r: R(t) held for the l + 1 ticks before it, which it cannot reach.
  const auto reach = [&](double r) {
    scratch = pending;
    double angle = 0.0;
    for (int i = 0; i < lag + 1; ++i) {
      Stepper::Push(scratch, r);
      angle = stepper.Advance(scratch);
    }
    return angle;
  };
  // M(t+l): R(t) has not acted yet.
  scratch = pending;
  double acting = pending.angle_deg;
  for (int i = 0; i < lag; ++i) {
    Stepper::Push(scratch, previous);
    acting = stepper.Advance(scratch);
  }
  return ChooseRequest(reach, lo, hi, target, acting);
}

// The duty u that gives target speed `speed` (deg/s) at load duty `load` and friction band
// `band` (the lines n..w* of ServoModelParams inverted), the least |u| where the speed is 0.
inline double DutyForSpeed(const ServoModelParams& params, double speed, double load, double band) {
  if (speed > 0.0) return load + speed / params.v_max_deg_s + band;
  if (speed < 0.0) return load + speed / params.v_max_deg_s - band;
  return load - std::clamp(load, -band, band);  // inside the band: as little duty as holds
}

// The extended model's request, unclamped, to take the joint from angle `angle_deg` with
// velocity `velocity_deg_s` at tick k-1 to angle `target_deg` at tick k (the request acting at
// k), and the duty it needs (beyond +-1 where the servo cannot: the request is then the least
// that saturates). The velocity at k must be (target - angle) / tick; with the velocity lag
// that takes the target speed w* = w + (w(k) - w) / (1 - exp(-tick / velocity_lag)), and the
// duty giving w* (DutyForSpeed) and the P-law give R = angle + u / (gain * kp).
struct PathStep {
  double request_deg;
  double duty;
};
inline PathStep InvertExtendedTick(const ExtendedStepper& stepper, double angle_deg,
                                   double velocity_deg_s, double target_deg) {
  const ServoModelParams& params = stepper.params;
  const double blend = servo_tick::VelocityBlend(params, stepper.tick_s);
  const double speed = (target_deg - angle_deg) / stepper.tick_s;
  const double target_speed = velocity_deg_s + (speed - velocity_deg_s) / blend;
  const double load = ServoLoadDuty(params, stepper.drive, angle_deg);
  const double band = params.friction_duty + params.friction_load_ratio * std::abs(load);
  const double duty = DutyForSpeed(params, target_speed, load, band);
  return {angle_deg + std::clamp(duty, -1.0, 1.0) / (params.gain_per_deg_kp * stepper.drive.kp),
          duty};
}

// The extended model's model-based request along the desired path (the paper's method carried
// over): R(t) acts on tick k = t + l + 1, and were the joint on the path at k - 1, at angle
// D(k-1) with velocity (D(k-1) - D(k-2)) / tick, InvertExtendedTick to D(k). `d_k2`, `d_k1`,
// `d_k`: D(k-2), D(k-1), D(k).
inline PathStep DesiredPathTick(const ExtendedStepper& stepper, double d_k2, double d_k1,
                                double d_k) {
  return InvertExtendedTick(stepper, d_k1, (d_k1 - d_k2) / stepper.tick_s, d_k);
}

// A receding horizon from the pending state at tick t (M(t), requests up to R(t-1)): the
// requests R(t..t+m-1) of `plan` (m >= 1; held beyond it) and the desired angles D(t..t+P)
// (P >= 1; the horizon's error is over M(t+1..t+P)).

// R(t + q): a past request of `pending` (q < 0) or the plan's (held beyond its end).
template <class State>
double HorizonRequest(const State& pending, std::span<const double> plan, int q) {
  if (q < 0) return pending.past_requests_deg[static_cast<size_t>(-q - 1)];
  return plan[std::min(static_cast<size_t>(q), plan.size() - 1)];
}

// The sum over j = 1..P of (M(t+j) - D(t+j))^2 under `plan`; `scratch` a state of the same
// size. Non-empty `angles` (size P + 1) gets M(t..t+P), for HorizonGradient.
template <class Stepper>
double HorizonError(const Stepper& stepper, const typename Stepper::State& pending,
                    typename Stepper::State& scratch, std::span<const double> plan,
                    std::span<const double> desired, std::span<double> angles,
                    double bound = std::numeric_limits<double>::infinity()) {
  scratch = pending;
  if (!angles.empty()) angles[0] = scratch.angle_deg;
  double sum = 0.0;
  for (size_t j = 1; j < desired.size(); ++j) {
    Stepper::Push(scratch, HorizonRequest(pending, plan, static_cast<int>(j) - 1));
    const double angle = stepper.Advance(scratch);
    if (!angles.empty()) angles[j] = angle;
    sum += (angle - desired[j]) * (angle - desired[j]);
    if (sum >= bound) return sum;
  }
  return sum;
}

// HorizonError for the extended model, the same arithmetic in the same order (so the same
// bits) without its per-tick costs: the model's coefficients and velocity blend computed once,
// the acting request read from the plan instead of pushed through the state's memory. The
// optimal plans' inner loop. `scratch` is not used. With a `bound`, it stops once the sum
// reaches it (a sum of squares only grows): a line search's rejected candidates cost less.
inline double HorizonError(const ExtendedStepper& stepper, const ServoModelState& pending,
                           ServoModelState& /*scratch*/, std::span<const double> plan,
                           std::span<const double> desired, std::span<double> angles,
                           double bound = std::numeric_limits<double>::infinity()) {
  const servo_tick::Coefficients c = servo_tick::CoefficientsOf(stepper.params, stepper.drive);
  const double blend = servo_tick::VelocityBlend(stepper.params, stepper.tick_s);
  const int lag = stepper.params.lag_ticks;
  double angle = pending.angle_deg;
  double velocity = pending.velocity_deg_s;
  if (!angles.empty()) angles[0] = angle;
  double sum = 0.0;
  for (size_t j = 1; j < desired.size(); ++j) {
    const double acting = HorizonRequest(pending, plan, static_cast<int>(j) - 1 - lag);
    servo_tick::Advance(c, stepper.tick_s, blend, acting, angle, velocity);
    if (!angles.empty()) angles[j] = angle;
    sum += (angle - desired[j]) * (angle - desired[j]);
    if (sum >= bound) return sum;
  }
  return sum;
}

// The derivatives of the extended model's target speed w* (ServoTargetSpeed) in the angle and
// in the request acting, at `angle_deg` and `request_deg`. Where w* is not differentiable (a
// saturated duty, the friction band's edge) the slope on the side the model's comparison takes.
struct TargetSpeedSlopes {
  double per_angle = 0.0;
  double per_request = 0.0;
};
// `c`: servo_tick::CoefficientsOf(p, drive), the model's own coefficients and load, so that the
// band is judged on w*'s bits.
inline TargetSpeedSlopes TargetSpeedDerivatives(const ServoModelParams& p,
                                                const servo_tick::Coefficients& c, double angle_deg,
                                                double request_deg) {
  constexpr double kRadPerDeg = std::numbers::pi / 180.0;
  const double duty_raw = c.duty_per_deg * (request_deg - angle_deg);
  const double duty_slope = std::abs(duty_raw) < 1.0 ? c.duty_per_deg : 0.0;
  const double load = servo_tick::LoadDuty(c, angle_deg);
  const double load_slope = c.load_duty_at_90 * servo_tick::CosDegrees(angle_deg) * kRadPerDeg;
  const double net = std::clamp(duty_raw, -1.0, 1.0) - load;
  const double band = p.friction_duty + p.friction_load_ratio * std::abs(load);
  // Inside the band w* is 0. With no band (band == 0) w* = v_max net is smooth through
  // net = 0, where the model's comparison would give the slope 0 and stall a descent at rest.
  if (band > 0.0 && std::abs(net) <= band) return {};
  const double load_sign = load > 0.0 ? 1.0 : (load < 0.0 ? -1.0 : 0.0);
  const double band_slope = p.friction_load_ratio * load_sign * load_slope;
  const double net_sign = net > 0.0 ? 1.0 : -1.0;
  return {p.v_max_deg_s * (-duty_slope - load_slope - net_sign * band_slope),
          p.v_max_deg_s * duty_slope};
}

// d HorizonError / d plan into `gradient` (size m), by the adjoint of the model's steps, from
// the angles a HorizonError of the same plan recorded.
inline void HorizonGradient(const ExtendedStepper& stepper, const ServoModelState& pending,
                            std::span<const double> plan, std::span<const double> desired,
                            std::span<const double> angles, std::span<double> gradient) {
  std::fill(gradient.begin(), gradient.end(), 0.0);
  const ServoModelParams& params = stepper.params;
  const servo_tick::Coefficients coefficients = servo_tick::CoefficientsOf(params, stepper.drive);
  const double blend = servo_tick::VelocityBlend(params, stepper.tick_s);
  const auto decisions = static_cast<int>(gradient.size());
  double angle_adjoint = 0.0;     // dE/dM(t+j+1) through the ticks after it
  double velocity_adjoint = 0.0;  // dE/dw(t+j+1) through the ticks after it
  for (int j = static_cast<int>(desired.size()) - 2; j >= 0; --j) {
    const auto k = static_cast<size_t>(j) + 1;
    // M(t+j+1) = M(t+j) + w(t+j+1) tick, w(t+j+1) = w(t+j) + blend (w*(M(t+j), R(t+j-l)) - w(t+j)).
    const double angle_total = 2.0 * (angles[k] - desired[k]) + angle_adjoint;
    const double velocity_total = angle_total * stepper.tick_s + velocity_adjoint;
    const int q = j - params.lag_ticks;
    const TargetSpeedSlopes slopes = TargetSpeedDerivatives(params, coefficients, angles[k - 1],
                                                            HorizonRequest(pending, plan, q));
    angle_adjoint = angle_total + velocity_total * blend * slopes.per_angle;
    velocity_adjoint = velocity_total * (1.0 - blend);
    if (q >= 0 && q < decisions) {
      gradient[static_cast<size_t>(q)] += velocity_total * blend * slopes.per_request;
    }
  }
}

inline void HorizonGradient(const PaperStepper& stepper, const JointModelState& pending,
                            std::span<const double> plan, std::span<const double> desired,
                            std::span<const double> angles, std::span<double> gradient) {
  std::fill(gradient.begin(), gradient.end(), 0.0);
  const JointModelParams& params = stepper.params;
  const double slope = params.v_max_deg_per_tick / params.theta0_deg;  // f' on its linear piece
  const auto decisions = static_cast<int>(gradient.size());
  double angle_adjoint = 0.0;  // dE/dM(t+j+1) through the ticks after it
  for (int j = static_cast<int>(desired.size()) - 2; j >= 0; --j) {
    const auto k = static_cast<size_t>(j) + 1;
    // M(t+j+1) = M(t+j) + (1/a) sum_{i=l+1}^{l+a} f(R(t+j+1-i) - M(t+j)) (eq. 3).
    const double angle_total = 2.0 * (angles[k] - desired[k]) + angle_adjoint;
    double slopes = 0.0;
    for (int i = params.lag_ticks + 1; i <= params.lag_ticks + params.accel_ticks; ++i) {
      const int q = j + 1 - i;
      const double x = HorizonRequest(pending, plan, q) - angles[k - 1];
      if (!(x > -params.theta0_deg && x < params.theta0_deg)) continue;  // f saturated
      slopes += slope;
      if (q >= 0 && q < decisions) {
        gradient[static_cast<size_t>(q)] += angle_total * slope / params.accel_ticks;
      }
    }
    angle_adjoint = angle_total * (1.0 - slopes / params.accel_ticks);
  }
}

}  // namespace leglab::servo_plan
