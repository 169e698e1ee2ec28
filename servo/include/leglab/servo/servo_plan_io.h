#pragma once

#include <optional>
#include <string>
#include <vector>

#include "leglab/model/joint_model.h"
#include "leglab/servo/servo_model.h"
#include "leglab/servo/servo_plan.h"
#include "leglab/servo/servo_planner.h"

namespace leglab {

/// One rung's fitted model of one motor, as log_fit.json's "models" gives it.
struct FittedModel {
  std::string rung;              ///< "paper" or "extended"
  std::string motor;             ///< e.g. "sts3250"
  double tick_s = 0.0;           ///< the tick the model was fitted on (s)
  JointModelParams paper;        ///< when rung is "paper"
  ServoModelParams extended;     ///< when rung is "extended"
  double top_speed_deg_s = 0.0;  ///< v_max_deg_s, or v_max_deg_per_tick / tick_s
};

/// Reads `models.<rung>.<motor>` from the log_fit.json at `path` (other fields ignored). With
/// an empty `motor` the file's only motor of that rung. Throws InputError naming the file and
/// the field on an unreadable file, malformed JSON, a missing or non-numeric field, a rung or
/// motor not in the file (listing those that are), or a model out of range
/// (ServoModelParamsProblem, JointModelParamsProblem; tick_s > 0).
FittedModel ReadFittedModel(const std::string& path, const std::string& rung,
                            const std::string& motor);

/// ReadFittedModel on the text of a log_fit.json; `source` starts its messages ("--model
/// '<file>'").
FittedModel ParseFittedModel(const std::string& text, const std::string& rung,
                             const std::string& motor, const std::string& source);

/// A plan as `plan` writes it (requests.csv, plan.json).
struct PlanResult {
  FittedModel model;
  ServoDrive drive;             ///< kp, mass and length (the paper's rung ignores them)
  ServoLimits limits;           ///< the requests' bounds; the speed limit is the model's
  std::vector<double> desired;  ///< D on the model's tick (deg)
  ServoPlan plan;               ///< the requests and their prediction
  std::vector<double> direct;   ///< the model's angles with the desired angles as requests
  /// Online (PlanDesiredOnline): the desired angles after each tick's the planner was given.
  std::optional<int> preview_ticks;
};

/// What `plan` computes once the model, drive and desired motion are read: PlanServoRequests
/// (extended rung) or PlanJointModelRequests (paper rung) with requests in [min_deg, max_deg]
/// changing at most at the model's top speed, and the direct prediction. Throws
/// std::invalid_argument as those do.
PlanResult PlanDesired(const FittedModel& model, const ServoDrive& drive,
                       std::vector<double> desired_deg, double min_deg, double max_deg,
                       PlanMethod method);

/// PlanDesired online: a ServoPlanner with `options` (its method, preview, budget) run tick by
/// tick on the model itself, each tick measuring what the model predicts. The requests and
/// predictions are the planner's; beyond_servo is the batch model-based plan's (a property of
/// the desired motion). Throws std::invalid_argument as ServoPlanner.
PlanResult PlanDesiredOnline(const FittedModel& model, const ServoDrive& drive,
                             std::vector<double> desired_deg, double min_deg, double max_deg,
                             const ServoPlannerOptions& options);

/// A desired motion read from --desired, before resampling.
struct DesiredServoMotion {
  std::vector<double> time_s;       ///< strictly increasing
  std::vector<double> desired_deg;  ///< D at each time
  bool is_log = false;              ///< a servo log: its requests, held between samples
  std::string motor;                ///< a BAM log's motor (else empty)
  std::optional<ServoDrive> drive;  ///< a BAM log's kp, mass and length
};

/// Reads --desired: a `.json` file as a BAM servo log and a CSV whose header starts
/// `time_s,request_deg` as leglab's servo log (ReadServoLog; the request column is the desired
/// motion), any other file as a desired CSV: the header `time_s,desired_deg`, then rows of two
/// plain decimal cells (as ReadServoLog's CSV), times strictly increasing, at least 2 rows.
/// Throws InputError naming the file, the row and the column.
DesiredServoMotion ReadDesiredMotion(const std::string& path);

/// `motion` on ticks of `tick_s` from its first time to its last (within 1e-9 s): a desired
/// CSV interpolated linearly, a log's requests held (Resample). Throws InputError beyond
/// 1,000,000 ticks.
std::vector<double> ResampleDesired(const DesiredServoMotion& motion, double tick_s,
                                    const std::string& path);

}  // namespace leglab
