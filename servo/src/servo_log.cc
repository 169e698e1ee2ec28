#include "leglab/servo/servo_log.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "leglab/core/format.h"
#include "leglab/servo/servo_model.h"

namespace leglab {
namespace {

// A sample this close to a tick is at it; also how far the grid may reach past the last sample.
constexpr double kTickTolerance_s = 1e-9;
// Bounds the memory of a resampled log (three arrays, 17 bytes a tick): 1.7 GB.
constexpr double kMaxTicks = 1e8;

// The median of `values` (reordered); the mean of the two middle ones for an even count.
double Median(std::vector<double>& values) {
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<long>(mid), values.end());
  const double upper = values[mid];
  if (values.size() % 2 == 1) return upper;
  const double lower = *std::max_element(values.begin(), values.begin() + static_cast<long>(mid));
  return 0.5 * (lower + upper);
}

void AppendIntervals(std::span<const ServoLogSample> samples, std::vector<double>& intervals) {
  for (size_t i = 1; i < samples.size(); ++i) {
    intervals.push_back(samples[i].time_s - samples[i - 1].time_s);
  }
}

void CheckResampleInput(std::span<const ServoLogSample> samples, double tick_s) {
  if (const std::string problem = KeyValueProblem(tick_s, kServoTickDoc); !problem.empty()) {
    throw std::invalid_argument("Resample: tick_s must be " + problem + ", got " +
                                FormatNumber(tick_s));
  }
  if (samples.size() < 2) {
    throw std::invalid_argument("Resample: needs at least 2 samples, got " +
                                std::to_string(samples.size()));
  }
  for (size_t i = 0; i < samples.size(); ++i) {
    if (!std::isfinite(samples[i].time_s)) {
      throw std::invalid_argument("Resample: sample " + std::to_string(i) +
                                  "'s time is not finite");
    }
    if (i > 0 && !(samples[i].time_s > samples[i - 1].time_s)) {
      throw std::invalid_argument("Resample: sample " + std::to_string(i) +
                                  "'s time is not after sample " + std::to_string(i - 1) + "'s");
    }
  }
}

// The number of ticks t0 + k * tick_s (k = 0, 1, ...) at or before t_end + kTickTolerance_s.
size_t TickCount(double t0, double t_end, double tick_s) {
  const double estimate = std::floor((t_end - t0 + kTickTolerance_s) / tick_s) + 1.0;
  if (estimate > kMaxTicks) {
    throw std::invalid_argument("Resample: a tick of " + std::to_string(tick_s) + " s over " +
                                std::to_string(t_end - t0) + " s makes more than 1e8 ticks");
  }
  // The estimate's division may round either way: settle it on the products themselves.
  auto n = static_cast<size_t>(estimate);
  const auto within = [&](size_t k) {
    return t0 + static_cast<double>(k) * tick_s <= t_end + kTickTolerance_s;
  };
  while (within(n)) ++n;
  while (n > 1 && !within(n - 1)) --n;
  return n;
}

// Tick `t` from the sample `before` (the last at or before t + tolerance) and the one after it.
void AddTick(std::span<const ServoLogSample> samples, size_t before, double t, ResampledLog& out) {
  const ServoLogSample& a = samples[before];
  out.request_deg.push_back(a.request_deg);
  if (std::abs(t - a.time_s) <= kTickTolerance_s || before + 1 == samples.size()) {
    out.measured_deg.push_back(a.measured_deg);
    out.torque_enabled.push_back(a.torque_enabled ? 1 : 0);
    return;
  }
  const ServoLogSample& b = samples[before + 1];
  const double w = (t - a.time_s) / (b.time_s - a.time_s);
  out.measured_deg.push_back(a.measured_deg + w * (b.measured_deg - a.measured_deg));
  out.torque_enabled.push_back(a.torque_enabled && b.torque_enabled ? 1 : 0);
}

}  // namespace

double MedianSampleInterval(std::span<const ServoLogSample> samples) {
  if (samples.size() < 2) {
    throw std::invalid_argument("MedianSampleInterval: needs at least 2 samples, got " +
                                std::to_string(samples.size()));
  }
  std::vector<double> intervals;
  AppendIntervals(samples, intervals);
  return Median(intervals);
}

double MedianSampleInterval(std::span<const ServoLog> logs) {
  std::vector<double> intervals;
  for (const ServoLog& log : logs) AppendIntervals(log.samples, intervals);
  if (intervals.empty()) {
    throw std::invalid_argument("MedianSampleInterval: no log has 2 samples (" +
                                std::to_string(logs.size()) + " logs)");
  }
  return Median(intervals);
}

ResampledLog Resample(std::span<const ServoLogSample> samples, double tick_s) {
  CheckResampleInput(samples, tick_s);
  const double t0 = samples.front().time_s;
  const size_t ticks = TickCount(t0, samples.back().time_s, tick_s);
  ResampledLog out;
  out.tick_s = tick_s;
  out.request_deg.reserve(ticks);
  out.measured_deg.reserve(ticks);
  out.torque_enabled.reserve(ticks);
  // Ticks and samples both advance in time: one pass over each.
  size_t before = 0;
  for (size_t k = 0; k < ticks; ++k) {
    const double t = t0 + static_cast<double>(k) * tick_s;
    while (before + 1 < samples.size() && samples[before + 1].time_s <= t + kTickTolerance_s) {
      ++before;
    }
    AddTick(samples, before, t, out);
  }
  return out;
}

}  // namespace leglab
