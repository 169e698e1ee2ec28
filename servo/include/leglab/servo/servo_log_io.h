#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "leglab/servo/servo_log.h"

namespace leglab {

/// How a servo log file is written.
enum class ServoLogFormat {
  kAuto,     ///< by the file's extension: `.json` is kBamJson, `.csv` is kCsv (any case)
  kCsv,      ///< leglab's CSV form (ReadServoLog)
  kBamJson,  ///< the JSON object of Rhoban/bam's logs, as shipped in data/servo_logs/
};

/// The longest motor or trajectory name (bytes): names go into file names and table cells.
inline constexpr size_t kMaxServoNameBytes = 100;

/// What a CSV log does not say itself: given by config keys.
struct ServoLogDefaults {
  std::string motor;      ///< servo type, e.g. "xl330"
  double kp = 0.0;        ///< the servo's position-gain register value (>= 0)
  double mass_kg = 0.0;   ///< pendulum mass (kg, >= 0; 0 = no load)
  double length_m = 0.0;  ///< pendulum length (m, >= 0)
};

/// The largest servo log file read, 64 MiB, refused by its size before it is read: a CSV of
/// 10^6 samples takes about 30 MB; BAM's JSON entries take about 200 bytes each, so a BAM
/// file this size holds about 300,000 of them (the shipped ones hold 273 to 1,510).
inline constexpr std::uintmax_t kMaxServoLogBytes = std::uintmax_t{64} << 20;
/// The most samples a servo log may have: 2,000,000 (an hour at 2 ms).
inline constexpr std::size_t kMaxServoLogSamples = 2'000'000;

/// Reads the servo log at `path`, in `format` (kAuto: by extension, anything but .csv and
/// .json refused). ServoLog::file is `path` as given.
///
/// CSV: the header `time_s,request_deg,measured_deg` or
/// `time_s,request_deg,measured_deg,torque_enabled`, then one sample a row: time (s), request
/// and measurement (deg), each a plain finite decimal (no '+', hex or spaces; the whole cell),
/// torque_enabled `0` or `1` (1 when the column is absent). Blank lines and a trailing '\r'
/// are ignored. The trajectory is the file's stem; motor, kp, mass and length come from
/// `csv_defaults`.
///
/// BAM JSON: one object with `mass` (kg), `length` (m), `kp`, `motor`, `trajectory` and
/// `entries`, each entry with `timestamp` (s), `goal_position` (the request, rad),
/// `position` (measured, rad) and `torque_enable` (bool); angles are converted to degrees,
/// other fields are ignored. `csv_defaults` is not used.
///
/// Both: a motor and trajectory name of at most kMaxServoNameBytes without control characters
/// (a newline would start a new line of log_fit.md), time stamps strictly increasing, at least
/// 2 samples, at least one with torque on,
/// every request and measurement within +-kMaxPlanAngleDeg (servo_plan.h), kp, mass and length
/// from 0 to kMaxServoKp, kMaxServoMassKg and kMaxServoLengthM, at most kMaxServoLogBytes and
/// kMaxServoLogSamples. Throws InputError (config.h), one line of at most about 300
/// characters naming the file and the row (CSV, counted from 1 after the header) or entry
/// (JSON, `entries[i]` from 0) and the column or field at fault, echoed cells cut to 40
/// characters with invisible ones escaped (a byte-order mark shows as \ufeff).
ServoLog ReadServoLog(const std::string& path, ServoLogFormat format,
                      const ServoLogDefaults& csv_defaults);

/// Checks a log given as values (built in memory, not read) as ReadServoLog checks a file:
/// a motor named, kp, mass and length within their bounds, at least 2 and at most
/// kMaxServoLogSamples samples, every time, request and measurement finite and the angles
/// within kMaxPlanAngleDeg, the times strictly increasing, the torque on in one sample at least.
/// Throws InputError "servo log '<file>': sample <i>, <column>: ..." (samples counted from 0).
void CheckServoLog(const ServoLog& log);

/// `log`'s samples in leglab's CSV form, with the torque column: each number as the shortest
/// text that reads back as the same double, so ReadServoLog of it gives `log`'s samples bit for
/// bit (motor, kp, mass and length are not in the CSV form: a CSV log takes them from its
/// config keys). Throws as CheckServoLog.
std::string ServoLogCsvText(const ServoLog& log);

}  // namespace leglab
