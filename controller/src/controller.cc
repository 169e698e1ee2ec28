#include "leglab/controller/controller.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

#include "leglab/core/units.h"

namespace leglab {

DesiredCycle OfflineCycleMemo::GetOrCompute(const char* name, const ControllerContext& context,
                                            const std::function<DesiredCycle()>& compute) {
  const std::lock_guard<std::mutex> lock(mutex_);
  for (const Entry& e : entries_) {
    if (e.name == name && e.models == context.models && e.limits == context.limits &&
        e.desired == context.desired) {
      return e.cycle;
    }
  }
  entries_.push_back({name, context.desired, context.models, context.limits, compute()});
  return entries_.back().cycle;
}

ApproximationMemo::ApproximationMemo(DesiredCycle desired,
                                     const std::array<double, kLegJoints>& v_max_deg_per_tick,
                                     int segments)
    : desired_(std::move(desired)), v_max_deg_per_tick_(v_max_deg_per_tick), segments_(segments) {}

const std::array<PiecewiseLinear, kLegJoints>& ApproximationMemo::Get() {
  std::call_once(once_, [this] {
    const auto period = static_cast<int>(desired_.size());
    std::vector<double> joint_desired(period);
    for (int j = 0; j < kLegJoints; ++j) {
      for (int t = 0; t < period; ++t) joint_desired[t] = desired_[t][j];
      fits_[j] = FitPiecewiseLinear(joint_desired, v_max_deg_per_tick_[j], {.segments = segments_},
                                    &(*caches_)[j]);
    }
  });
  return fits_;
}

std::shared_ptr<ApproximationMemo> ApproximationMemo::ForOtherModels(
    const std::array<double, kLegJoints>& v_max_deg_per_tick) const {
  auto other = std::make_shared<ApproximationMemo>(desired_, v_max_deg_per_tick, segments_);
  other->caches_ = caches_;
  return other;
}

const PiecewiseLinear& ControllerContext::Approximation(int joint) const {
  static const PiecewiseLinear kNone;
  return approximations == nullptr ? kNone : approximations->Get()[joint];
}

ControllerContext MakeControllerContext(DesiredCycle desired,
                                        const std::array<JointModelParams, kLegJoints>& models,
                                        const LegGeometry& geometry, int pwl_segments) {
  ValidateLegGeometry(geometry);
  ControllerContext context =
      MakeControllerContext(std::move(desired), models, geometry.limits, pwl_segments);
  context.geometry = geometry;
  return context;
}

ControllerContext MakeControllerContext(DesiredCycle desired,
                                        const std::array<JointModelParams, kLegJoints>& models,
                                        const std::array<JointLimits, kLegJoints>& limits,
                                        int pwl_segments) {
  if (desired.empty()) throw std::invalid_argument("controller: the desired cycle is empty");
  const auto period = static_cast<int>(desired.size());
  if (const std::string problem =
          KeyValueProblem(pwl_segments, WithRange(kPwlSegmentsDoc, 1, period));
      !problem.empty()) {
    throw std::invalid_argument("config: controller.pwl_segments must be " + problem +
                                " (the ticks of a step), got " + std::to_string(pwl_segments));
  }
  ControllerContext context{std::move(desired), models, limits, {}, 0, {}};
  std::array<double, kLegJoints> v_max{};
  for (int j = 0; j < kLegJoints; ++j) {
    const std::string joint(kLegJointNames[j]);
    try {
      ValidateJointModelParams(models[j]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("controller: model of the " + joint + ": " + e.what());
    }
    if (!(limits[j].lower_rad < limits[j].upper_rad)) {
      throw std::invalid_argument("controller: limits of the " + joint +
                                  " must have lower < upper");
    }
    // The fit's own input checks now, so that a bad cycle fails here as before, not on use.
    std::vector<double> joint_desired(period);
    for (int t = 0; t < period; ++t) joint_desired[t] = context.desired[t][j];
    ValidatePiecewiseLinearInput(joint_desired, models[j].v_max_deg_per_tick);
    v_max[j] = models[j].v_max_deg_per_tick;
  }
  context.approximations =
      std::make_shared<ApproximationMemo>(context.desired, v_max, pwl_segments);
  return context;
}

void VisitModelSourceKey(KeyVisitor& v, ModelSource& source) {
  v.Key("model", source, kModelSourceNames,
        {.description = "the models it inverts: step_tests (identified, or given; the default, "
                        "the paper's model) or walk (each joint's fitted to the plant's response "
                        "to the paper's requests on the walk, pooled with the step tests; "
                        "track.yaml ships it for optimal)"});
}

void VisitObjectiveKeys(KeyVisitor& v, Objective& objective, double& joint_weight,
                        double& request_smoothing) {
  v.Key("objective", objective, kObjectiveNames,
        {.description = "what it minimises under the model: joint (each joint's RMS error, as "
                        "the paper scores a joint; the default, which needs no geometry) or foot "
                        "(the foot's distance from its path, what the experiments score; "
                        "track.yaml ships it)"});
  v.Key("joint_weight", joint_weight,
        {.min = 0,
         .max = 100,
         .description = "foot objective: weight of the joints' own errors, relative to their "
                        "mean effect at the foot (0: the foot alone)"});
  v.Key("request_smoothing", request_smoothing,
        {.min = 0,
         .max = 1e6,
         .description = "move suppression on the request cycle's second difference, relative to "
                        "the objective's mean weight; 0 (the default): none, the exact optimum "
                        "under the model; track.yaml ships 0.3 for optimal, track_stand.yaml 10 "
                        "for both (docs/design/request-smoothing.md)"});
}

void RequireSettlingModels(const ControllerContext& context, std::string_view mode) {
  for (int j = 0; j < kLegJoints; ++j) {
    const JointModelParams& p = context.models[j];
    if (SettlesOnEveryCycle(p)) continue;
    char numbers[128];
    std::snprintf(numbers, sizeof numbers, "v_max %.6g deg/tick is at least 2 theta_0, %.6g deg",
                  p.v_max_deg_per_tick, 2.0 * p.theta0_deg);
    throw std::invalid_argument(std::string(mode) + ": the " + std::string(kLegJointNames[j]) +
                                "'s model has no cyclic steady state (" + numbers +
                                ": eq. 3 swings about a request for ever)");
  }
}

LegAngles ClampToLimits(const LegAngles& request_deg,
                        const std::array<JointLimits, kLegJoints>& limits) {
  LegAngles clamped;
  for (int j = 0; j < kLegJoints; ++j) {
    clamped[j] =
        std::clamp(request_deg[j], RadToDeg(limits[j].lower_rad), RadToDeg(limits[j].upper_rad));
  }
  return clamped;
}

}  // namespace leglab
