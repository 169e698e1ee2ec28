#pragma once

#include <array>
#include <string_view>

namespace leglab {

/// Length of one control tick, ms: the Aibo takes one joint request and reports one measured
/// angle per joint every 8 ms (the paper's time unit t_u).
inline constexpr double kTickMs = 8.0;

/// Joints per leg. Every per-joint array in leglab is ordered rotator, abductor, knee.
inline constexpr int kLegJoints = 3;

/// Index of each joint in a leg's per-joint arrays, body to foot.
enum LegJoint : int { kRotator = 0, kAbductor = 1, kKnee = 2 };

/// The joints' names, in LegJoint order: the URDF joint names, the config's and the output
/// files' joint labels.
inline constexpr std::array<std::string_view, kLegJoints> kLegJointNames = {"rotator", "abductor",
                                                                            "knee"};

/// One value per joint of a leg, in LegJoint order (degrees unless a name says otherwise).
using LegAngles = std::array<double, kLegJoints>;

}  // namespace leglab
