#include "leglab/model/joint_model_plant.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "leglab/core/units.h"

namespace leglab {

JointModelPlant::JointModelPlant(const std::array<JointModelParams, kLegJoints>& models,
                                 const std::array<JointLimits, kLegJoints>& limits)
    : models_(models) {
  LegAngles start{};
  for (int j = 0; j < kLegJoints; ++j) {
    const std::string joint(kLegJointNames[j]);
    try {
      ValidateJointModelParams(models_[j]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("model plant, " + joint + ": " + e.what());
    }
    if (!(limits[j].lower_rad < limits[j].upper_rad)) {
      throw std::invalid_argument("model plant, " + joint + ": limits must have lower < upper");
    }
    lower_deg_[j] = RadToDeg(limits[j].lower_rad);
    upper_deg_[j] = RadToDeg(limits[j].upper_rad);
    start[j] = std::clamp(0.0, lower_deg_[j], upper_deg_[j]);
  }
  Reset(start);
}

void JointModelPlant::Reset(const LegAngles& pose_deg) {
  for (int j = 0; j < kLegJoints; ++j) {
    if (!std::isfinite(pose_deg[j]) || pose_deg[j] < lower_deg_[j] || pose_deg[j] > upper_deg_[j]) {
      throw std::invalid_argument("joint '" + std::string(kLegJointNames[j]) + "': pose " +
                                  std::to_string(pose_deg[j]) + " deg is outside its limits [" +
                                  std::to_string(lower_deg_[j]) + ", " +
                                  std::to_string(upper_deg_[j]) + "] deg");
    }
    states_[j] = RestState(models_[j], pose_deg[j]);
  }
  reading_ = {pose_deg, pose_deg, pose_deg};
}

void SetPlantModelSetting(JointModelParams& params, std::string_view key, double value) {
  constexpr std::string_view kSection = "plant_model.";
  const std::string name(key.substr(std::min(key.size(), kSection.size())));
  // The key's declared range, as the config loader checks it (KeyAssigner does not check).
  for (const KeyRow& row :
       ListKeys(JointModelParams{}, [](KeyVisitor&v, JointModelParams&p) { VisitKeys(v, p); })) {
    if (row.key != name || !key.starts_with(kSection)) continue;
    if (const std::string problem = KeyValueProblem(value, row.doc); !problem.empty()) {
      throw std::invalid_argument(std::string(key) + " must be " + problem + ", got " +
                                  FormatNumber(value, NumberStyle::kReadable));
    }
  }
  KeyAssigner assigner(name, value);
  if (key.starts_with(kSection)) {
    try {
      VisitKeys(assigner, params);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string(kSection) + e.what());
    }
  }
  if (!assigner.assigned()) {
    std::string valid;
    for (const KeyRow& row :
         ListKeys(JointModelParams{}, [](KeyVisitor&v, JointModelParams&p) { VisitKeys(v, p); })) {
      valid += (valid.empty() ? "" : ", ") + std::string(kSection) + row.key;
    }
    throw std::invalid_argument(std::string(key) +
                                " cannot change on the model plant (can: " + valid + ")");
  }
  if (const std::string problem = JointModelParamsProblem(params); !problem.empty()) {
    throw std::invalid_argument(std::string(kSection) + problem);
  }
}

void JointModelPlant::ChangeSettings(std::span<const PlantSetting> settings) {
  std::array<JointModelParams, kLegJoints> changed = models_;
  for (const PlantSetting& setting : settings) {
    for (JointModelParams& p : changed) SetPlantModelSetting(p, setting.key, setting.value);
  }
  for (int j = 0; j < kLegJoints; ++j) {
    std::vector<double>& past = states_[j].past_requests_deg;
    const size_t memory =
        static_cast<size_t>(changed[j].lag_ticks) + static_cast<size_t>(changed[j].accel_ticks);
    past.resize(memory, past.back());  // newest first: the oldest is at the back
    models_[j] = changed[j];
  }
}

const PlantReading& JointModelPlant::Tick(const LegAngles& request_deg) {
  for (int j = 0; j < kLegJoints; ++j) {
    if (!std::isfinite(request_deg[j])) {
      throw std::invalid_argument("request for joint '" + std::string(kLegJointNames[j]) +
                                  "' must be finite");
    }
    const double applied = std::clamp(request_deg[j], lower_deg_[j], upper_deg_[j]);
    reading_.applied_deg[j] = applied;
    reading_.true_deg[j] = StepJointModel(models_[j], states_[j], applied);
  }
  reading_.measured_deg = reading_.true_deg;
  return reading_;
}

}  // namespace leglab
