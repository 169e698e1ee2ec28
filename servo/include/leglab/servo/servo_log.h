#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace leglab {

/// The columns of a servo log's samples as leglab's CSV log spells them, in order (the fourth
/// optional): identify reads them so, and the Python ServoLog's arrays and the first columns of
/// log_<motor>_<name>.csv are named so.
struct ServoLogColumnNames {
  std::string_view time_s = "time_s";
  std::string_view request_deg = "request_deg";
  std::string_view measured_deg = "measured_deg";
  std::string_view torque_enabled = "torque_enabled";
};
inline constexpr ServoLogColumnNames kServoLogColumns;
/// The same names in the CSV log's order.
inline constexpr std::array<std::string_view, 4> kServoLogColumnList{
    kServoLogColumns.time_s, kServoLogColumns.request_deg, kServoLogColumns.measured_deg,
    kServoLogColumns.torque_enabled};

/// One recorded sample of a servo log.
struct ServoLogSample {
  double time_s = 0.0;         ///< time stamp (s), strictly increasing within a log
  double request_deg = 0.0;    ///< the position request sent to the servo (deg)
  double measured_deg = 0.0;   ///< the position the servo reported (deg)
  bool torque_enabled = true;  ///< false while the servo is limp
};

/// A servo log as recorded: what drove it, what load and gain it ran under, and its samples.
struct ServoLog {
  std::string file;        ///< where it was read from, as given (for messages and tables)
  std::string motor;       ///< servo type, e.g. "xl330" (a model is fitted per motor)
  std::string trajectory;  ///< the request's shape, e.g. "sin_sin" (for leave-one-out)
  double kp = 0.0;         ///< the servo's position-gain setting (its register value)
  double mass_kg = 0.0;    ///< pendulum mass (kg) ; 0 = no load
  double length_m = 0.0;   ///< pendulum length (m)
  std::vector<ServoLogSample> samples;
};

/// A log on a uniform tick: tick k is at samples.front().time_s + k * tick_s, k = 0..N-1, for
/// every such time up to the last sample's (inclusive, within 1e-9 s). The three arrays have N
/// entries each.
struct ResampledLog {
  double tick_s = 0.0;                  ///< the tick (s)
  std::vector<double> request_deg;      ///< zero-order hold: the latest request sent at or
                                        ///< before the tick (what a servo sees) (deg)
  std::vector<double> measured_deg;     ///< linear interpolation of the measurement between
                                        ///< the samples around the tick (deg)
  std::vector<uint8_t> torque_enabled;  ///< 1 only when both samples around the tick (or the
                                        ///< sample at it) have torque on, else 0
};

/// The median of the successive time differences samples[i + 1].time_s - samples[i].time_s (s);
/// of an even number of differences, the mean of the two middle ones. Throws
/// std::invalid_argument when there are fewer than 2 samples.
double MedianSampleInterval(std::span<const ServoLogSample> samples);

/// The median (as above) of the successive time differences of all `logs` pooled (s): a log of
/// n samples contributes n - 1 differences. Throws std::invalid_argument when the logs hold no
/// difference at all (no log has 2 samples).
double MedianSampleInterval(std::span<const ServoLog> logs);

/// `samples` on a uniform tick of `tick_s` (s), as ResampledLog describes. A sample within
/// 1e-9 s of a tick counts as at it: its request and measurement are the tick's, and its torque
/// flag alone decides the tick's. Throws std::invalid_argument when `tick_s` is not a finite
/// positive number, there are fewer than 2 samples, a time stamp is not finite or not after
/// the one before it (the message names the index), or the grid would have more than 10^8 ticks.
ResampledLog Resample(std::span<const ServoLogSample> samples, double tick_s);

}  // namespace leglab
