#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "leglab/model/joint_model.h"
#include "leglab/servo/servo_model.h"

namespace leglab {

/// What a plan may ask of a servo: every request R(t) in [min_deg, max_deg], and
/// |R(t) - R(t-1)| <= max_speed_deg_s * tick_s (R(-1): the desired angle at t = 0, where the
/// model starts at rest).
struct ServoLimits {
  double min_deg = -180.0;       ///< least request (deg), finite, < max_deg
  double max_deg = 180.0;        ///< greatest request (deg), finite
  double max_speed_deg_s = 0.0;  ///< fastest change of the request (deg/s), > 0
};

/// How the requests are chosen.
enum class PlanMethod {
  /// The paper's inversion generalised, tick by tick: R(t) makes the model's M(t+l+1) the
  /// desired D(t+l+1) given the requests before it, by bisection on R(t) within the limits.
  /// Where several requests give the best reachable angle (a friction band, a saturated duty)
  /// the least-effort one: the nearest to M(t+l), the angle the model has when R(t) first acts.
  kModelBased,
  /// Least sum over the trajectory of (M(t) - D(t))^2 within the limits, by projected
  /// limited-memory BFGS from the kModelBased plan, accepting only steps that lower the sum (so
  /// never worse than kModelBased; a local optimum). The gradient is exact, by the adjoint of
  /// the model's steps (one pass forward and one back); the projection clamps the requests in
  /// time order to the limits and the speed limit. Cost per iteration: about 3 N model steps
  /// for the gradient and N per tried step, so O(N); at most kOptimalMaxIterations iterations,
  /// and a long motion block by block (kOptimalBlockTicks), so that its cost per tick is
  /// bounded.
  kOptimal,
};

/// The requests that descend each tick in the online kOptimal planner's default preview
/// (ServoPlanner): the preview is the model's lag, the hand-over and these.
inline constexpr int kOptimalWindowTicks = 60;
/// kOptimal's most iterations (each one gradient and a backtracking line search) on a motion
/// of one block, and the online planner's default cap a tick.
inline constexpr int kOptimalMaxIterations = 200;
/// The batch kOptimal plan of a motion longer than kOptimalBlockTicks + kOptimalOverlapTicks
/// ticks keeps kOptimalBlockTicks requests of each problem it solves, each solved with the
/// next kOptimalOverlapTicks ticks in at most kOptimalBlockIterations (PlanMethod::kOptimal),
/// so that its cost per tick does not grow with the motion's length: the iterations a kept
/// tick gets are a one-block motion's (each iteration's cost grows with the ticks it spans).
inline constexpr size_t kOptimalBlockTicks = 1000;
inline constexpr size_t kOptimalOverlapTicks = 250;
inline constexpr int kOptimalBlockIterations =
    kOptimalMaxIterations * static_cast<int>(kOptimalBlockTicks) /
    static_cast<int>(kOptimalBlockTicks + kOptimalOverlapTicks);
static_assert(kOptimalBlockIterations == 160);
/// A desired angle missed by more than this (deg) under the best request counts as beyond
/// the servo: the bisection itself is exact to about 1e-10 deg.
inline constexpr double kBeyondServoToleranceDeg = 1e-6;

/// The bounds a plan holds its inputs to, so that every number it computes is finite: a plan
/// never holds a NaN or an infinity, and what would make one is refused, naming the field.
/// |desired angle|, |limit| (deg): kServoAngleDoc's.
inline constexpr double kMaxPlanAngleDeg = kServoAngleDoc.max;
inline constexpr double kMinPlanTickS = kServoTickDoc.min;  ///< the shortest tick (s)
inline constexpr double kMaxPlanTickS = kServoTickDoc.max;  ///< the longest tick (s)
/// max_speed_deg_s and a model's top speed (deg/s): the servo model's own bound.
inline constexpr double kMaxPlanSpeedDegS = kMaxServoSpeedDegS;
/// m g L / stall torque: a load a thousand times what the servo can hold still.
inline constexpr double kMaxLoadToStall = 1e3;
/// velocity_lag_s / tick_s: the velocity moves at least a 10^-9th of its way a tick.
inline constexpr double kMaxLagOverTick = 1e9;
/// The paper's model's slope v_max / theta_0 (per tick): theta_0 at least 10^-9 v_max.
inline constexpr double kMaxSpeedSlopePerTick = 1e9;
/// The declared range of the paper's model's slope v_max / theta_0 in a plan (per tick).
inline constexpr KeyDoc kSpeedSlopeDoc{
    .min = 0, .max = kMaxSpeedSlopePerTick, .min_open = true, .unit = "per tick"};

/// Empty when PlanServoRequests of this model and drive on ticks of `tick_s` keeps every
/// number finite for any desired motion and limits within kMaxPlanAngleDeg (the model in
/// range, ServoModelParamsProblem; kp positive and the duty per degree gain_per_deg_kp * kp
/// and its inverse finite; mass and length zero or positive with the load at most
/// kMaxLoadToStall times the stall torque; v_max_deg_s at most kMaxPlanSpeedDegS;
/// velocity_lag_s at most kMaxLagOverTick ticks; tick_s from kMinPlanTickS to kMaxPlanTickS);
/// otherwise what is wrong, naming the fields.
std::string ServoPlanProblem(const ServoModelParams& params, const ServoDrive& drive,
                             double tick_s);

/// Empty when `limits` are ones a plan takes: min_deg < max_deg, both within
/// kMaxPlanAngleDeg, and max_speed_deg_s in (0, kMaxPlanSpeedDegS]; otherwise what is wrong.
std::string ServoLimitsProblem(const ServoLimits& limits);

/// The same for PlanJointModelRequests: the model in range (JointModelParamsProblem), its slope
/// v_max / theta_0 at most kMaxSpeedSlopePerTick, its top speed v_max / tick_s at most
/// kMaxPlanSpeedDegS, tick_s from kMinPlanTickS to kMaxPlanTickS.
std::string JointModelPlanProblem(const JointModelParams& params, double tick_s);

/// A plan: the requests, what the model predicts under them, and where the desired angles
/// are beyond the servo. All vectors have the desired trajectory's size N.
struct ServoPlan {
  std::vector<double> request_deg;    ///< R(t), within the limits (deg)
  std::vector<double> predicted_deg;  ///< the model's M(t) under request_deg, from rest at D(0)
  /// 1 at t when the kModelBased inversion for D(t) missed it by more than
  /// kBeyondServoToleranceDeg (saturation, the limits); the same flags for kOptimal.
  std::vector<uint8_t> beyond_servo;
  int beyond_servo_ticks = 0;  ///< how many flags are 1
};

/// Requests (deg) for the extended model to follow `desired_deg` D(0..N-1), one a tick of
/// `tick_s` seconds, within `limits`, chosen by `method`; the model starts at rest at D(0), and
/// D(N-1) is held beyond the end. Throws std::invalid_argument on a model, drive or tick
/// ServoPlanProblem refuses, an empty desired trajectory or an angle in it beyond
/// kMaxPlanAngleDeg, limits beyond kMaxPlanAngleDeg or min_deg >= max_deg, max_speed_deg_s not
/// in (0, kMaxPlanSpeedDegS], or D(0) outside [min_deg, max_deg].
ServoPlan PlanServoRequests(const ServoModelParams& params, const ServoDrive& drive, double tick_s,
                            std::span<const double> desired_deg, const ServoLimits& limits,
                            PlanMethod method);

/// PlanServoRequests for the paper's model (eq. 3), whose ticks are those of `desired_deg`,
/// `tick_s` seconds each (it converts the speed limit). Throws as PlanServoRequests does, on
/// a model or tick as JointModelPlanProblem says.
ServoPlan PlanJointModelRequests(const JointModelParams& params, double tick_s,
                                 std::span<const double> desired_deg, const ServoLimits& limits,
                                 PlanMethod method);

/// The extended model's angles M(0..N-1) under `requests_deg` R(0..N-1), from rest at R(0)
/// (the prediction of sending them as they are). Empty for no requests.
std::vector<double> PredictServoAngles(const ServoModelParams& params, const ServoDrive& drive,
                                       double tick_s, std::span<const double> requests_deg);

/// The paper model's angles M(0..N-1) under `requests_deg`, from rest at R(0).
std::vector<double> PredictJointModelAngles(const JointModelParams& params,
                                            std::span<const double> requests_deg);

}  // namespace leglab
