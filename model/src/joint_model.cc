#include "leglab/model/joint_model.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "leglab/core/format.h"

namespace leglab {
namespace {

// Velocity of eq. 3 at tick t: the average of f over R(t-l-1) .. R(t-l-a), with `request_at(j)`
// returning R(t-j).
template <typename RequestAt>
double ModelVelocity(const JointModelParams& p, double angle_deg, RequestAt request_at) {
  double sum = 0.0;
  for (int i = p.lag_ticks + 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
    sum += SpeedResponse(p, request_at(i) - angle_deg);
  }
  return sum / p.accel_ticks;
}

}  // namespace

void VisitKeys(KeyVisitor& v, JointModelParams& params, const JointModelDocs& docs) {
  const JointModelNames& n = kJointModelNames;
  v.Key(n.v_max_deg_per_tick, params.v_max_deg_per_tick, docs.v_max_deg_per_tick);
  v.Key(n.theta0_deg, params.theta0_deg, docs.theta0_deg);
  v.Key(n.lag_ticks, params.lag_ticks, docs.lag_ticks);
  v.Key(n.accel_ticks, params.accel_ticks, docs.accel_ticks);
  // f's slope inside (-theta_0, theta_0): an infinite or subnormal one makes f(0) NaN or the
  // model's steps meaningless. (Unset values, 0, are the ranges' to report.)
  const double slope = params.v_max_deg_per_tick / params.theta0_deg;
  if (params.v_max_deg_per_tick > 0.0 && params.theta0_deg > 0.0 && !std::isnormal(slope)) {
    v.Fail(n.theta0_deg, "such that v_max_deg_per_tick / theta0_deg is a normal number, got " +
                             FormatNumber(params.v_max_deg_per_tick) + " / " +
                             FormatNumber(params.theta0_deg));
  }
}

std::string JointModelParamsProblem(const JointModelParams& params) {
  return KeysProblem(params,
                     [](KeyVisitor& v, JointModelParams& p) { VisitKeys(v, p, kAnyJointModel); });
}

bool SettlesOnEveryCycle(const JointModelParams& p) {
  return p.v_max_deg_per_tick < 2.0 * p.theta0_deg;
}

void ValidateJointModelParams(const JointModelParams& p) {
  if (const std::string problem = JointModelParamsProblem(p); !problem.empty()) {
    throw std::invalid_argument("joint model: " + problem);
  }
}

double SpeedResponse(const JointModelParams& p, double x_deg) {
  if (x_deg >= p.theta0_deg) return p.v_max_deg_per_tick;
  if (x_deg <= -p.theta0_deg) return -p.v_max_deg_per_tick;
  return x_deg * (p.v_max_deg_per_tick / p.theta0_deg);
}

JointModelState RestState(const JointModelParams& p, double angle_deg) {
  ValidateJointModelParams(p);
  return {angle_deg, std::vector<double>(p.lag_ticks + p.accel_ticks, angle_deg)};
}

double AdvanceJointModel(const JointModelParams& p, JointModelState& state) {
  const auto& past = state.past_requests_deg;
  assert(static_cast<int>(past.size()) == p.lag_ticks + p.accel_ticks);
  state.angle_deg += ModelVelocity(p, state.angle_deg, [&](int i) { return past[i - 1]; });
  return state.angle_deg;
}

void PushJointModelRequest(JointModelState& state, double request_deg) {
  auto& past = state.past_requests_deg;
  // Newest first: shift the history by one and put R(t) in front.
  std::copy_backward(past.begin(), past.end() - 1, past.end());
  past.front() = request_deg;
}

double StepJointModel(const JointModelParams& p, JointModelState& state, double request_deg) {
  const double angle = AdvanceJointModel(p, state);
  PushJointModelRequest(state, request_deg);
  return angle;
}

std::vector<double> SimulateJointModel(const JointModelParams& p,
                                       std::span<const double> requests_deg,
                                       const JointModelState& initial) {
  ValidateJointModelParams(p);
  if (static_cast<int>(initial.past_requests_deg.size()) != p.lag_ticks + p.accel_ticks) {
    throw std::invalid_argument("joint model: the initial state must remember l + a = " +
                                std::to_string(p.lag_ticks + p.accel_ticks) + " requests");
  }
  const auto n = static_cast<long>(requests_deg.size());
  std::vector<double> angles(n);
  double angle = initial.angle_deg;
  for (long t = 0; t < n; ++t) {
    angle += ModelVelocity(p, angle, [&](int i) {
      const long j = t - i;
      return j >= 0 ? requests_deg[j] : initial.past_requests_deg[-j - 1];
    });
    angles[t] = angle;
  }
  return angles;
}

std::vector<double> CyclicSteadyState(const JointModelParams& p,
                                      std::span<const double> cycle_requests_deg,
                                      double tolerance_deg, int max_cycles) {
  ValidateJointModelParams(p);
  const auto period = static_cast<long>(cycle_requests_deg.size());
  if (period == 0) throw std::invalid_argument("joint model: the request cycle is empty");

  auto request_at = [&](long t) {
    const long j = ((t % period) + period) % period;
    return cycle_requests_deg[j];
  };
  const double mean = std::accumulate(cycle_requests_deg.begin(), cycle_requests_deg.end(), 0.0) /
                      static_cast<double>(period);
  std::vector<double> angles(period, mean);
  double angle = mean;
  double previous_change = 0.0;
  for (int cycle = 0; cycle < max_cycles; ++cycle) {
    double change = 0.0;
    for (long t = 0; t < period; ++t) {
      angle += ModelVelocity(p, angle, [&](int i) { return request_at(t - i); });
      change = std::max(change, std::abs(angle - angles[t]));
      angles[t] = angle;
    }
    // The cycle map contracts by about rho = change / previous_change a cycle, so the distance
    // left to the steady state is about change * rho / (1 - rho): stop when that is small,
    // not merely when one cycle changed little (a slow contraction changes little per cycle).
    if (cycle > 1) {
      const double rho = previous_change > 0.0 ? change / previous_change : 0.0;
      if (change == 0.0 ||
          (rho < 1.0 && change * rho / (1.0 - rho) <= tolerance_deg && change <= tolerance_deg)) {
        return angles;
      }
    }
    previous_change = change;
  }
  throw std::runtime_error("joint model: no cyclic steady state after " +
                           std::to_string(max_cycles) + " cycles (the model oscillates)");
}

}  // namespace leglab
