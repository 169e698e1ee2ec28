#include "leglab/servo/servo_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "leglab/core/format.h"
#include "servo_model_tick.h"

namespace leglab {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A positive, or a non-negative, finite value in `unit`.
constexpr KeyDoc Positive(std::string_view unit, std::string_view description) {
  return {.min = 0,
          .max = kInfinity,
          .min_open = true,
          .max_open = true,
          .unit = unit,
          .description = description};
}
constexpr KeyDoc NonNegative(std::string_view unit, std::string_view description) {
  return {.min = 0, .max = kInfinity, .max_open = true, .unit = unit, .description = description};
}

}  // namespace

void servo_tick::CheckRecording(const ServoRecording& recording) {
  const size_t n = recording.request_deg.size();
  if (recording.measured_deg.size() != n || recording.scored.size() != n) {
    throw std::invalid_argument("servo recording: request, measured and scored sizes differ");
  }
  if (std::string problem = ServoDriveProblem(recording.drive); !problem.empty()) {
    throw std::invalid_argument("servo recording: " + problem);
  }
  for (size_t t = 0; t < n; ++t) {
    if (!std::isfinite(recording.request_deg[t]) || !std::isfinite(recording.measured_deg[t])) {
      throw std::invalid_argument("servo recording: sample " + std::to_string(t) +
                                  " is not finite");
    }
  }
}

void VisitKeys(KeyVisitor& v, ServoDrive& drive) {
  v.Key("kp", drive.kp, kServoKpDoc);
  v.Key("mass_kg", drive.mass_kg, kServoMassDoc);
  v.Key("length_m", drive.length_m, kServoLengthDoc);
}

std::string ServoDriveProblem(const ServoDrive& drive) {
  return KeysProblem(drive, [](KeyVisitor& v, ServoDrive& d) { VisitKeys(v, d); });
}

void VisitKeys(KeyVisitor& v, ServoModelParams& params) {
  v.Key("gain_per_deg_kp", params.gain_per_deg_kp,
        Positive("", "duty per degree of error per unit of kp"));
  v.Key("v_max_deg_s", params.v_max_deg_s, kServoVMaxDoc);
  v.Key("stall_torque_nm", params.stall_torque_nm, Positive("N m", "torque at full duty"));
  v.Key("friction_duty", params.friction_duty,
        NonNegative("", "friction band with no load (duty)"));
  v.Key("friction_load_ratio", params.friction_load_ratio,
        NonNegative("", "the band's growth per unit of load duty"));
  v.Key("velocity_lag_s", params.velocity_lag_s, Positive("s", "the velocity's time constant"));
  v.Key(kJointModelNames.lag_ticks, params.lag_ticks,
        WithDescription(kAnyJointModel.lag_ticks, "l: ticks before a request starts to act"));
}

std::string ServoModelParamsProblem(const ServoModelParams& params) {
  return KeysProblem(params, [](KeyVisitor& v, ServoModelParams& p) { VisitKeys(v, p); });
}

std::vector<double> RecordedRequestsUpTo(const ServoRecording& recording, size_t t, size_t count) {
  std::vector<double> requests(count);
  for (size_t i = 0; i < count; ++i) requests[i] = recording.request_deg[t >= i ? t - i : 0];
  return requests;
}

ServoModelState ServoRestState(const ServoModelParams& params, double angle_deg) {
  ServoModelState state;
  state.angle_deg = angle_deg;
  state.past_requests_deg.assign(static_cast<size_t>(params.lag_ticks) + 1, angle_deg);
  return state;
}

double ServoLoadDuty(const ServoModelParams& params, const ServoDrive& drive, double angle_deg) {
  return servo_tick::LoadDuty(servo_tick::CoefficientsOf(params, drive), angle_deg);
}

double ServoTargetSpeed(const ServoModelParams& params, const ServoDrive& drive, double angle_deg,
                        double error_deg) {
  return servo_tick::TargetSpeed(servo_tick::CoefficientsOf(params, drive), angle_deg, error_deg);
}

double AdvanceServoModel(const ServoModelParams& params, const ServoDrive& drive, double tick_s,
                         ServoModelState& state) {
  servo_tick::Advance(servo_tick::CoefficientsOf(params, drive), tick_s,
                      servo_tick::VelocityBlend(params, tick_s), state.past_requests_deg.back(),
                      state.angle_deg, state.velocity_deg_s);
  return state.angle_deg;
}

void PushServoModelRequest(ServoModelState& state, double request_deg) {
  std::vector<double>& past = state.past_requests_deg;
  // R(t) joins the front; R(t-1-l), now used, leaves the back.
  std::rotate(past.rbegin(), past.rbegin() + 1, past.rend());
  past.front() = request_deg;
}

double StepServoModel(const ServoModelParams& params, const ServoDrive& drive, double tick_s,
                      ServoModelState& state, double request_deg) {
  const double angle = AdvanceServoModel(params, drive, tick_s, state);
  PushServoModelRequest(state, request_deg);
  return angle;
}

std::vector<double> PredictServoRecording(const ServoModelParams& params,
                                          const ServoRecording& recording, double tick_s) {
  servo_tick::CheckRecording(recording);
  if (const std::string problem = KeyValueProblem(tick_s, kServoTickDoc); !problem.empty()) {
    throw std::invalid_argument("servo recording: tick_s must be " + problem + ", got " +
                                FormatNumber(tick_s));
  }
  ServoModelState state;
  return PredictDrivenRuns(
      recording,
      [&](size_t t) {
        state.angle_deg = recording.measured_deg[t];
        state.velocity_deg_s = 0.0;
        state.past_requests_deg =
            RecordedRequestsUpTo(recording, t, static_cast<size_t>(params.lag_ticks) + 1);
      },
      [&](size_t t) {
        return StepServoModel(params, recording.drive, tick_s, state, recording.request_deg[t]);
      });
}

}  // namespace leglab
