#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "leglab/core/config_keys.h"
#include "leglab/model/joint_model.h"

namespace leglab {

/// Gravity's acceleration in the load's torque (m/s^2).
inline constexpr double kGravityMS2 = 9.81;

/// What a servo is asked to do besides following its request: its position-gain setting and
/// the load it holds, a point mass on a massless arm (a pendulum whose angle 0 hangs straight
/// down). These come from the log or the plan, never from a fit.
struct ServoDrive {
  double kp = 0.0;        ///< the servo's position-gain register (its own units), > 0
  double mass_kg = 0.0;   ///< the load's mass (kg), >= 0 (0: no load)
  double length_m = 0.0;  ///< from the axis to the load's centre of mass (m), >= 0
};

/// The physical bounds of a drive, wherever one is given (a log, the logs.* keys, plan's
/// flags, the Python package): beyond any hobby servo, so a larger value is a typo.
inline constexpr double kMaxServoKp = 1e6;       ///< the gain register (its own units)
inline constexpr double kMaxServoMassKg = 1000;  ///< the load's mass (kg)
inline constexpr double kMaxServoLengthM = 10;   ///< the load's arm (m)

/// The declared range of each of ServoDrive's values (VisitKeys), which plan's flags and the
/// logs.* keys take too.
inline constexpr KeyDoc kServoKpDoc{
    .min = 0,
    .max = kMaxServoKp,
    .min_open = true,
    .description = "the servo's position-gain register (its own units)"};
inline constexpr KeyDoc kServoMassDoc{
    .min = 0, .max = kMaxServoMassKg, .unit = "kg", .description = "the load's mass"};
inline constexpr KeyDoc kServoLengthDoc{
    .min = 0,
    .max = kMaxServoLengthM,
    .unit = "m",
    .description = "from the axis to the load's centre of mass"};

/// A log's kp as it is read (a file, logs.kp): kServoKpDoc's range from 0, where 0 means not
/// given (a CSV log's kp then comes from logs.kp; a fit refuses a drive still without one).
inline constexpr KeyDoc kLogKpDoc = WithDescription(
    WithRange(kServoKpDoc, 0, kMaxServoKp), "a CSV log's position-gain setting (register units)");

/// The declared range of the tick a servo's model runs on (s): what its fits, predictions,
/// plans and resampling take (1 us to 10 s).
inline constexpr KeyDoc kServoTickDoc{
    .min = 1e-6, .max = 10, .unit = "s", .description = "the tick the servo's model runs on"};

/// The declared range of a servo's angle (deg): a request, a measurement, a desired angle or a
/// limit (278 turns either way), within which every number a plan computes stays finite.
inline constexpr KeyDoc kServoAngleDoc{
    .min = -1e5, .max = 1e5, .unit = "deg", .description = "a servo's angle"};

/// ServoDrive's three values, declared once (see KeyVisitor) with the ranges above: what
/// ServoDriveProblem checks for the model's functions, plan's flags and the Python package.
void VisitKeys(KeyVisitor& visitor, ServoDrive& drive);

/// Empty when `drive` keeps its declaration (VisitKeys); otherwise what is wrong, naming the
/// field ("kp must be in (0, 1000000], got 0").
std::string ServoDriveProblem(const ServoDrive& drive);

/// The extended joint model: the paper's request-space model (eq. 2-3) given the external
/// torque of a load and the servo's gain, fitted once per servo type for every gain setting.
/// One tick of `tick_s` seconds from M(t-1) with velocity w(t-1):
///   e    = R(t-1-l) - M(t-1)                         request error, deg (l: lag_ticks)
///   u    = clamp(gain_per_deg_kp * kp * e, -1, 1)    the servo's P-law duty, saturating
///   g    = m * 9.81 * L * sin(M(t-1)) / stall_torque_nm   duty that holds the load
///   n    = u - g                                     duty left to move the joint
///   F    = friction_duty + friction_load_ratio * |g| the friction band (duty)
///   w*   = v_max_deg_s * sign(n) * max(|n| - F, 0)   speed the net duty settles to
///   w(t) = w(t-1) + (1 - exp(-tick_s / velocity_lag_s)) * (w* - w(t-1))
///   M(t) = M(t-1) + w(t) * tick_s
/// Without load and friction, w* is the paper's f (eq. 2) with theta_0 = 1 / (gain * kp) and
/// top speed v_max: the paper's averaging of f over a ticks becomes a first-order velocity lag,
/// and the request still acts through a pure delay of l ticks. A request-space model: the
/// angle, not a torque, is what it predicts and what its inversion asks for.
struct ServoModelParams {
  double gain_per_deg_kp = 0.0;      ///< duty per degree of error per unit of kp, > 0
  double v_max_deg_s = 0.0;          ///< speed at full net duty (deg/s), > 0
  double stall_torque_nm = 0.0;      ///< torque at full duty (N m), > 0
  double friction_duty = 0.0;        ///< friction band with no load (duty), >= 0
  double friction_load_ratio = 0.0;  ///< band's growth per unit of load duty, >= 0
  double velocity_lag_s = 0.0;       ///< the velocity's time constant (s), > 0
  int lag_ticks = 0;                 ///< l: ticks before a request starts to act, >= 0

  friend bool operator==(const ServoModelParams&, const ServoModelParams&) = default;
};

/// The fastest a servo model's v_max_deg_s may be (deg/s; 27,800 turns a second): beyond any
/// servo, and small enough that a plan's speeds stay far from overflow.
inline constexpr double kMaxServoSpeedDegS = 1e7;

/// The declared range of v_max_deg_s, which `logs.v_max_deg_s` (a published speed) takes too.
inline constexpr KeyDoc kServoVMaxDoc{.min = 0,
                                      .max = kMaxServoSpeedDegS,
                                      .min_open = true,
                                      .unit = "deg/s",
                                      .description = "speed at full net duty"};

/// The extended model's seven values, declared once (see KeyVisitor) with the ranges their
/// comments give: what ServoModelParamsProblem checks for the model's functions, plan's
/// reading of log_fit.json and the Python package.
void VisitKeys(KeyVisitor& visitor, ServoModelParams& params);

/// Empty when `params` keeps its declaration (VisitKeys); otherwise what is wrong, naming the
/// field ("velocity_lag_s must be in (0, inf) s, got 0").
std::string ServoModelParamsProblem(const ServoModelParams& params);

/// What the model remembers between ticks: M(t-1), w(t-1) and R(t-1), ..., R(t-1-l) (newest
/// first; size l + 1).
struct ServoModelState {
  double angle_deg = 0.0;
  double velocity_deg_s = 0.0;
  std::vector<double> past_requests_deg;
};

/// A joint at rest at `angle_deg`: no velocity, every remembered request equal to the angle.
ServoModelState ServoRestState(const ServoModelParams& params, double angle_deg);

/// The duty g that holds the load still at `angle_deg` (ServoModelParams), signed.
double ServoLoadDuty(const ServoModelParams& params, const ServoDrive& drive, double angle_deg);

/// The speed w* (deg/s) the net duty settles to at angle `angle_deg` under request error
/// `error_deg` (the lines e..w* of ServoModelParams).
double ServoTargetSpeed(const ServoModelParams& params, const ServoDrive& drive, double angle_deg,
                        double error_deg);

/// One tick of the model: `state` holds M(t-1), w(t-1) and the past requests on entry, and
/// M(t), w(t) and the requests up to R(t) = `request_deg` on return. Returns M(t). R(t) first
/// acts at t + l + 1, as in the paper's model.
double StepServoModel(const ServoModelParams& params, const ServoDrive& drive, double tick_s,
                      ServoModelState& state, double request_deg);

/// StepServoModel in two halves, for a caller that must see M(t) before choosing R(t) (an
/// online planner): AdvanceServoModel moves `state` from M(t-1), w(t-1) to M(t), w(t) and
/// returns M(t) (the requests are left as they were); PushServoModelRequest then remembers
/// R(t). Advance and push together are StepServoModel, bit for bit.
double AdvanceServoModel(const ServoModelParams& params, const ServoDrive& drive, double tick_s,
                         ServoModelState& state);
void PushServoModelRequest(ServoModelState& state, double request_deg);

/// A recorded run of a servo on a uniform tick, as the fit and the scores see it.
struct ServoRecording {
  ServoDrive drive;
  std::vector<double> request_deg;   ///< R(t), deg
  std::vector<double> measured_deg;  ///< the angle measured at t, deg
  std::vector<uint8_t> scored;       ///< 1 where the servo was driven (torque on), else 0
};

/// The requests R(t), R(t-1), ..., R(t-count+1) of a recording, newest first, the first
/// request standing in for those before tick 0: a model's memory when it starts after tick t.
std::vector<double> RecordedRequestsUpTo(const ServoRecording& recording, size_t t, size_t count);

/// Open-loop prediction over a recording's driven runs, for any model: `start(t)` puts the
/// model as it stands after tick t, started from the measured angle at rest (the first driven
/// tick of a run, predicted as measured); `step(t)` steps it with R(t) and returns M(t).
/// Undriven ticks are predicted as measured. Returns M(0..N-1).
template <class Start, class Step>
std::vector<double> PredictDrivenRuns(const ServoRecording& recording, Start&& start, Step&& step) {
  std::vector<double> predicted(recording.measured_deg);
  bool running = false;
  for (size_t t = 0; t < predicted.size(); ++t) {
    if (recording.scored[t] == 0) {
      running = false;
    } else if (!running) {
      start(t);
      running = true;
    } else {
      predicted[t] = step(t);
    }
  }
  return predicted;
}

/// The open-loop prediction of a recording: at tick 0 and at the first driven tick after
/// undriven ones the model starts from the measured angle at rest (no velocity), remembering
/// the recorded requests before it (the first request before tick 0), and then runs on the
/// recorded requests alone. Undriven ticks are predicted as measured. Size N.
/// Throws std::invalid_argument on mismatched sizes or tick_s <= 0.
std::vector<double> PredictServoRecording(const ServoModelParams& params,
                                          const ServoRecording& recording, double tick_s);

}  // namespace leglab
