#pragma once

#include <array>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

#include "leglab/core/column_doc.h"
#include "leglab/core/leg.h"

namespace leglab {

/// What a plant measures besides the joint angles: the test stand's instruments. The one
/// record of them: a plant's reading (PlantReading) and the simulated world's stand
/// (sim::LegWorld::stand_state()) both use it. For reporting only: the experiments record it,
/// no controller is given it. All zero for a plant without a stand (the leg in the air, the
/// model plant). The stand's design: docs/design/stand.md.
struct PlantTelemetry {
  /// The floor's force on the foot, N, body (= world) axes: x forward, y left, z up (a loaded
  /// foot has z > 0). In a plant's reading the mean over the tick; in the world's stand state
  /// that of the latest physics step.
  std::array<double, 3> contact_force_n{};
  /// The stand's carriage height above the shoulder's walking height, mm (StandConfig), at the
  /// end of the tick or physics step.
  double carriage_z_mm = 0.0;
  /// How far the foot has slid along the floor while loaded, mm, cumulative: the tangential
  /// speed of the foot's material point at the contact relative to the floor's surface (a
  /// treadmill belt's included), integrated over every physics step whose normal force exceeds
  /// LegWorld::kLoadedContactN (rolling of the ball is not slip). Counted since the plant was
  /// built or reset in a reading, since the world was built in its stand state; a step's slip
  /// is the difference across it.
  double slip_mm = 0.0;
  /// The stand's sled (the body's horizontal give) forward (x) and to the left (y) of its
  /// spring's rest, mm; 0 without a sled.
  double sled_x_mm = 0.0;
  double sled_y_mm = 0.0;
};

/// One number of PlantTelemetry as tables and the Python package name it: its column (name,
/// unit, description) and how to read it. The one place these names are spelled:
/// foot_<mode>.csv's instrument columns and the Python package's Reading properties and
/// Plant.run() arrays take them from here.
struct TelemetryColumn {
  ColumnDoc doc;
  double (*value)(const PlantTelemetry& telemetry);
};

/// The floor's force on the foot, axis by axis, in foot_<mode>.csv's order (up first).
inline constexpr std::array<TelemetryColumn, 3> kContactForceColumns{{
    {{"contact_fz_n", "N", "the floor's force on the foot, up, mean over the tick"},
     [](const PlantTelemetry& t) { return t.contact_force_n[2]; }},
    {{"contact_fx_n", "N", "the floor's force on the foot, forward, mean over the tick"},
     [](const PlantTelemetry& t) { return t.contact_force_n[0]; }},
    {{"contact_fy_n", "N", "the floor's force on the foot, left, mean over the tick"},
     [](const PlantTelemetry& t) { return t.contact_force_n[1]; }},
}};

/// The stand's other instruments, one number each.
inline constexpr TelemetryColumn kCarriageColumn{
    {"carriage_z_mm", "mm", "the stand's carriage above the shoulder's walking height"},
    [](const PlantTelemetry& t) { return t.carriage_z_mm; }};
inline constexpr std::array<TelemetryColumn, 4> kStandColumns{{
    kCarriageColumn,
    {{"slip_mm", "mm", "how far the foot has slid while loaded since the plant was made or reset"},
     [](const PlantTelemetry& t) { return t.slip_mm; }},
    {{"sled_x_mm", "mm", "the stand's sled forward of its rest; 0 without a sled"},
     [](const PlantTelemetry& t) { return t.sled_x_mm; }},
    {{"sled_y_mm", "mm", "the stand's sled to the left of its rest; 0 without a sled"},
     [](const PlantTelemetry& t) { return t.sled_y_mm; }},
}};

/// What a plant reports at the end of a control tick, degrees.
struct PlantReading {
  LegAngles measured_deg{};    ///< the sensors' reading (what a controller may see)
  LegAngles true_deg{};        ///< the exact joint angles (for scoring and plotting only)
  LegAngles applied_deg{};     ///< the latest request as the servos took it (clamped to the limits)
  PlantTelemetry telemetry{};  ///< the stand's instruments (for reporting only)
};

/// One setting of a running plant to change: its name as the config writes it (e.g.
/// "servo.max_speed_deg_s") and its new value, in that key's units.
struct PlantSetting {
  std::string key;
  double value = 0.0;
};

/// A leg that takes one request per 8 ms control tick and reports its angles: ros2_control's
/// write() / read() pair folded into one call. The simulated leg (sim::LegSim) and the joint
/// model as an ideal plant (JointModelPlant) implement it; experiments drive any of them the
/// same way.
///
/// Timing: Tick(R(t)) sends the request of tick t and returns the reading taken right after
/// it, at the end of tick t: the paper's R(t) and actual angle at t.
class Plant {
 public:
  virtual ~Plant() = default;

  /// Puts the leg at rest at `pose_deg` with its servos holding that pose (every remembered
  /// request equal to it); Read() then holds one reading of that pose. Does not advance time.
  /// Throws std::invalid_argument naming the joint when an angle is non-finite or outside the
  /// joint's limits.
  virtual void Reset(const LegAngles& pose_deg) = 0;

  /// One control tick: `request_deg` goes to the servos (each value clamped into its joint's
  /// limits, as the servo does), the leg moves for 8 ms, and the reading at the end of the
  /// tick is returned. Throws std::invalid_argument naming the joint for a non-finite request.
  virtual const PlantReading& Tick(const LegAngles& request_deg) = 0;

  /// The latest reading (of the pose after Reset(), or at the end of the latest tick).
  virtual const PlantReading& Read() const = 0;

  /// What kind of plant this is, for messages and outputs ("sim", "model").
  virtual std::string_view name() const = 0;

  /// Changes settings of the running plant between two ticks, as wear or a swapped part would:
  /// the motion, the remembered requests and the noise stream carry on, only the settings
  /// differ from the next Tick() on. The settings are applied in order; all are checked before
  /// any is applied. Throws std::invalid_argument naming the key for a key this plant does not
  /// have or a value out of its range (the plant is then unchanged). A plant without
  /// changeable settings throws for every key (this default).
  virtual void ChangeSettings(std::span<const PlantSetting> settings) {
    if (!settings.empty()) {
      throw std::invalid_argument("the " + std::string(name()) + " plant cannot change " +
                                  settings.front().key);
    }
  }
};

}  // namespace leglab
