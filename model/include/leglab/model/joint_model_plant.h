#pragma once

#include <array>
#include <string_view>

#include "leglab/core/plant.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/kinematics.h"

namespace leglab {

/// The paper's joint model (eq. 3) as an ideal plant: each joint moves exactly as its model
/// says and is read exactly (no sensor noise); requests are clamped into the joint limits, as
/// the servos do. What a controller achieves here is what it achieves when the model is
/// right, so comparing a controller on this plant and on the simulated leg separates the
/// policy's own error from the model's mismatch with the plant.
class JointModelPlant final : public Plant {
 public:
  /// `models`: each joint's model (validated: std::invalid_argument naming the joint);
  /// `limits`: each joint's limits, radians (lower < upper). Starts at rest at the pose
  /// nearest 0 inside the limits.
  JointModelPlant(const std::array<JointModelParams, kLegJoints>& models,
                  const std::array<JointLimits, kLegJoints>& limits);

  void Reset(const LegAngles& pose_deg) override;
  const PlantReading& Tick(const LegAngles& request_deg) override;
  const PlantReading& Read() const override { return reading_; }
  std::string_view name() const override { return "model"; }

  /// Joint j's model.
  const JointModelParams& model(int joint) const { return models_[joint]; }

 private:
  std::array<JointModelParams, kLegJoints> models_;
  std::array<double, kLegJoints> lower_deg_{};
  std::array<double, kLegJoints> upper_deg_{};
  std::array<JointModelState, kLegJoints> states_;
  PlantReading reading_;
};

}  // namespace leglab
