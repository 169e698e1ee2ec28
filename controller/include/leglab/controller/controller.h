#pragma once

#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/core/leg.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/line_inverse.h"

namespace leglab {

/// One cycle of desired joint angles: desired[t][j] for tick t = 0..T-1, degrees. The
/// trajectory repeats with period T (one walking step).
using DesiredCycle = std::vector<LegAngles>;

/// A request policy for one leg. Once per 8 ms control tick the experiment hands it the tick
/// and the angles just measured, and sends the angles it returns to the servos. Controllers
/// see no simulator type (ros2_control's update(time, period) in miniature).
class JointController {
 public:
  virtual ~JointController() = default;

  /// Requested angles (deg) for tick `tick` (0, 1, 2, ... from the start of the run), given the
  /// angles measured right after the previous request.
  virtual LegAngles Update(long tick, const LegAngles& measured_deg) = 0;

  /// The mode's name, as chosen in the config.
  virtual std::string_view name() const = 0;
};

/// What a controller is built from: the `controller.*` config keys.
struct ControllerSpec {
  std::string mode = "direct";     ///< one of ControllerModes()
  int shift_ticks = 0;             ///< time_shift: requests lead the desired angles by k ticks
  CmMethod cm = CmMethod::kExact;  ///< model_based: closed-form or exact C_m
  int pwl_segments = 8;            ///< model_based: segments of each joint's approximation
};

/// The valid mode names: direct, time_shift, model_based.
const std::vector<std::string>& ControllerModes();

/// Builds the controller `spec.mode` for the desired cycle, with each joint's model (used by
/// model_based only). Throws std::invalid_argument for an unknown mode (listing the valid ones),
/// an empty cycle or a bad parameter, and what model_based's construction throws.
std::unique_ptr<JointController> MakeController(
    const ControllerSpec& spec, const DesiredCycle& desired,
    const std::array<JointModelParams, kLegJoints>& models);

}  // namespace leglab
