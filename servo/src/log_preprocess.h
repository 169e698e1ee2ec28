#pragma once

// The log fit's first step, internal to leglab::servo_io: the configured and given logs read
// and named, and each resampled on its motor's tick (split at pauses, glitches left out).
// log_fit.cc fits and scores what it returns.

#include <vector>

#include "leglab/servo/log_fit.h"
#include "log_fit_report.h"

namespace leglab::log_fit {

/// logs.train and logs.validate (files, or folders' .json and .csv logs; relative paths from
/// the working directory, else from leglab's data folder) read by `config.format`, then
/// `given`: training logs first, each in the order given, named <motor>_<file stem>. Throws
/// InputError (via FailConfig) naming the key or file: no training log, a missing file or
/// folder, a file given twice, two logs of one name, a bad log.
std::vector<Log> ReadLogs(const LogFitConfig& config, const std::vector<GivenServoLog>& given);

/// `log` resampled on `tick_s` into its recording and times: its samples split at every pause
/// over logs.gap_s (a sample alone between two pauses is dropped), each glitch's measurement
/// over logs.glitch_deg replaced by its neighbours' line, and one undriven tick between
/// segments. Throws InputError naming the log and the key: too many ticks, a tick under
/// kMinTickPerSampleInterval of the median sample interval, no segment, no driven tick, a kp
/// out of range.
void Resample(Log& log, double tick_s, const LogFitConfig& config);

}  // namespace leglab::log_fit
