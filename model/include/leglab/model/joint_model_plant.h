#pragma once

#include <array>
#include <span>
#include <string_view>

#include "leglab/core/plant.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/kinematics.h"

namespace leglab {

/// Sets `key`, one of "plant_model.v_max_deg_per_tick", "plant_model.theta0_deg",
/// "plant_model.lag_ticks", "plant_model.accel_ticks" (the config's names), in `params`.
/// Throws std::invalid_argument naming the key for another key, a lag or acceleration time
/// that is not a whole number, or a model JointModelParamsProblem rejects.
void SetPlantModelSetting(JointModelParams& params, std::string_view key, double value);

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

  /// Plant: changes every joint's model from the next tick on; keys
  /// "plant_model.v_max_deg_per_tick", "plant_model.theta0_deg", "plant_model.lag_ticks",
  /// "plant_model.accel_ticks" (SetPlantModelSetting, applied to every joint). The angle carries
  /// on; a longer memory (l + a) repeats the oldest remembered request, a shorter one drops the
  /// oldest. Throws std::invalid_argument naming the key for another key or an invalid model.
  void ChangeSettings(std::span<const PlantSetting> settings) override;

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
