#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/core/config_keys.h"

namespace leglab {

/// Parameters of the paper's joint model (its Table 1): what identification fits.
/// Angles are in degrees and time in control ticks of 8 ms, the paper's units. There are no
/// default values (a model is identified or given); the paper's own is paper::kTable1.
struct JointModelParams {
  double v_max_deg_per_tick = 0.0;  ///< v_max: the joint's top speed
  double theta0_deg = 0.0;          ///< theta_0: request-actual difference that gives top speed
  int lag_ticks = 0;                ///< l: ticks before a request starts to act
  int accel_ticks = 0;              ///< a: ticks over which the velocity is averaged

  friend bool operator==(const JointModelParams&, const JointModelParams&) = default;
};

/// The most ticks a model's lag l or averaging window a may span. A model remembers l + a
/// requests and the planners' cost grows with them; the bound keeps that memory small while
/// covering the log fit's longest window (logs.window_max_s, 1 s) on logs sampled at 1 kHz.
inline constexpr int kMaxModelTicks = 1000;

/// A joint model's four values' names, as the config keys, the JSON fields and the CSV columns
/// spell them, in VisitKeys' order.
struct JointModelNames {
  std::string_view v_max_deg_per_tick = "v_max_deg_per_tick";
  std::string_view theta0_deg = "theta0_deg";
  std::string_view lag_ticks = "lag_ticks";
  std::string_view accel_ticks = "accel_ticks";
};
inline constexpr JointModelNames kJointModelNames;

/// The declared ranges of a joint model's four values.
struct JointModelDocs {
  KeyDoc v_max_deg_per_tick;
  KeyDoc theta0_deg;
  KeyDoc lag_ticks;
  KeyDoc accel_ticks;
};

/// A joint model of a leg's joint in 8 ms ticks, as the config keys take it (`model.*`,
/// `plant_model.*`, `adaptive.initial_model.*`), and Python's JointModel, identify's search
/// ranges and identify's check of what it fits with them: a fit outside these is refused as no
/// joint model (a stand that holds the foot, a servo that hardly moves).
inline constexpr JointModelDocs kJointModelKeys{
    .v_max_deg_per_tick = {.min = 0.01,
                           .max = 45,
                           .unit = "deg/tick",
                           .description = "v_max: the joint's top speed (45 deg/tick is "
                                          "5600 deg/s)"},
    .theta0_deg = {.min = 0.01,
                   .max = 180,
                   .unit = "deg",
                   .description = "theta_0: the request-actual difference that gives the top "
                                  "speed"},
    .lag_ticks = {.min = 0,
                  .max = 50,
                  .unit = "ticks",
                  .description = "l: ticks before a request starts to act (eq. 3)"},
    .accel_ticks = {.min = 1,
                    .max = 50,
                    .unit = "ticks",
                    .description = "a: ticks over which the speed response is averaged "
                                   "(eq. 3)"}};

/// Any joint model, in any tick: what the model's functions and the planners take, and what a
/// log fit may give (its tick is the log's, and a servo that never saturates fits a theta_0
/// beyond a turn). Positive speeds up to kMaxModelDegrees, l and a up to kMaxModelTicks.
inline constexpr double kMaxModelDegrees = 1e6;
inline constexpr JointModelDocs kAnyJointModel{
    .v_max_deg_per_tick = WithRange(kJointModelKeys.v_max_deg_per_tick, 0, kMaxModelDegrees, true),
    .theta0_deg = WithRange(kJointModelKeys.theta0_deg, 0, kMaxModelDegrees, true),
    .lag_ticks = WithRange(kJointModelKeys.lag_ticks, 0, kMaxModelTicks),
    .accel_ticks = WithRange(kJointModelKeys.accel_ticks, 1, kMaxModelTicks)};

/// The four keys of a joint model, declared once (see KeyVisitor), with the ranges `docs`; and
/// the rule that f's slope v_max / theta_0 is a normal number.
void VisitKeys(KeyVisitor& visitor, JointModelParams& params,
               const JointModelDocs& docs = kJointModelKeys);

/// Empty when `params` is a joint model (kAnyJointModel); otherwise what is wrong, naming the
/// field ("theta0_deg must be in (0, 1000000] deg, got -1").
std::string JointModelParamsProblem(const JointModelParams& params);

/// Throws std::invalid_argument "joint model: <problem>" unless JointModelParamsProblem is
/// empty.
void ValidateJointModelParams(const JointModelParams& params);

/// The speed response f of eq. 2 (deg/tick) to a request-actual difference `x_deg`:
/// linear with slope v_max / theta_0 inside (-theta_0, theta_0), saturated at +-v_max outside.
double SpeedResponse(const JointModelParams& params, double x_deg);

/// What the model remembers between ticks: the angle M(t-1) and the requests
/// R(t-1), R(t-2), ..., R(t-l-a) (newest first; size l + a).
struct JointModelState {
  double angle_deg = 0.0;
  std::vector<double> past_requests_deg;
};

/// A joint at rest at `angle_deg`: every remembered request equals that angle.
JointModelState RestState(const JointModelParams& params, double angle_deg);

/// One step of eq. 3: M(t) = M(t-1) + (1/a) sum_{i=l+1}^{l+a} f(R(t-i) - M(t-1)).
/// `state` holds M(t-1) and the past requests on entry and M(t) and the requests up to
/// R(t) = `request_deg` on return. Returns M(t). R(t) itself first acts at t + l + 1.
double StepJointModel(const JointModelParams& params, JointModelState& state, double request_deg);

/// StepJointModel in two halves, for a caller that must see M(t) before choosing R(t) (an
/// online planner): AdvanceJointModel moves `state` from M(t-1) to M(t) and returns it (the
/// requests are left as they were); PushJointModelRequest then remembers R(t). Advance and
/// push together are StepJointModel, bit for bit.
double AdvanceJointModel(const JointModelParams& params, JointModelState& state);
void PushJointModelRequest(JointModelState& state, double request_deg);

/// Runs eq. 3 over `requests_deg` R(0..N-1) from `initial` (M(-1) and the requests before
/// t = 0). Returns M(0..N-1).
std::vector<double> SimulateJointModel(const JointModelParams& params,
                                       std::span<const double> requests_deg,
                                       const JointModelState& initial);

/// Whether eq. 3 settles under every request cycle: v_max < 2 theta_0. One step of eq. 3 is
/// M -> g(M) = M + (1/a) sum_i f(R_i - M), whose slope 1 - (1/a) sum_i f'(R_i - M) lies in
/// [1 - v_max / theta_0, 1] (f' is v_max / theta_0 on f's linear piece, 0 where it saturates).
/// With v_max < 2 theta_0 every step is non-expanding and contracts wherever a term is linear,
/// so a repeated cycle is drawn to a steady state (one of an interval of them only where every
/// term of the cycle saturates, see CyclicSteadyState's start); with v_max >= 2 theta_0 a step near
/// a constant request overshoots it by as much as it started off (or more), and eq. 3 swings about
/// the request for ever. A servo that is fitted so (a near bang-bang one) has no steady state for
/// the modes that need one.
bool SettlesOnEveryCycle(const JointModelParams& params);

/// The cyclic steady state of eq. 3 under a request cycle R(0..T-1) repeated forever (the
/// paper's experiments run "many steps continuously"): the cycle is repeated from rest at
/// the mean request until the largest change of an angle over the last cycle, and the
/// distance to the limit that the observed contraction from cycle to cycle implies, are both
/// at most `tolerance_deg`.
/// Returns M(0..T-1) of that cycle. Throws std::runtime_error if it has not settled after
/// `max_cycles` cycles (an oscillating parameter set), std::invalid_argument on an empty cycle.
std::vector<double> CyclicSteadyState(const JointModelParams& params,
                                      std::span<const double> cycle_requests_deg,
                                      double tolerance_deg = 1e-10, int max_cycles = 100000);

}  // namespace leglab
