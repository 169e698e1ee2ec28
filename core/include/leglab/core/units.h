#pragma once

#include <numbers>

namespace leglab {

/// Radians per degree. Paper units (degrees, ticks) live at the edges; convert once, here.
inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;

/// `angle_deg` in radians.
constexpr double DegToRad(double angle_deg) { return angle_deg * kRadPerDeg; }

/// `angle_rad` in degrees.
constexpr double RadToDeg(double angle_rad) { return angle_rad / kRadPerDeg; }

}  // namespace leglab
