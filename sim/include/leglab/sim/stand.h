#pragma once

#include <array>

namespace leglab::sim {

/// What the single-leg test stand measures after a physics step (all zero without a stand).
/// The stand itself (StandConfig: a carriage on a vertical rail carrying a load, optionally on
/// a horizontal sled, a floor or treadmill belt under the foot) is built by LegWorld; its design
/// choices are in docs/design/stand.md.
struct StandState {
  /// The floor's force on the foot over the latest physics step, N, world (= body) axes:
  /// x forward, y left, z up (so a loaded foot has z > 0).
  std::array<double, 3> contact_force_n{};
  /// The carriage's height above the shoulder's walking height, mm (StandConfig).
  double carriage_z_mm = 0.0;
  /// Distance the foot has slid along the floor while loaded since the world was built, mm:
  /// the tangential speed of the foot's material point at the contact relative to the floor's
  /// surface (the treadmill belt's, StandConfig::belt_speed_mm_per_s), integrated over every
  /// physics step whose normal force exceeds LegWorld::kLoadedContactN. Rolling of the ball is
  /// not slip.
  double slip_mm = 0.0;
  /// The sled's position along x (forward) and y (left) from its spring's rest, mm; 0 without
  /// a sled.
  double sled_x_mm = 0.0;
  double sled_y_mm = 0.0;
};

}  // namespace leglab::sim
