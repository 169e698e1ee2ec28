#include "leglab/controller/adaptive_controller.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "leglab/core/units.h"
#include "leglab/model/piecewise_linear.h"
#include "leglab/model/request_synthesis.h"

namespace leglab {
namespace {

constexpr double kNoFit = std::numeric_limits<double>::quiet_NaN();

// A joint model's declaration `docs` with l and a within the window fit's search ranges (the
// identification's defaults), which the estimates never leave.
JointModelDocs WithinTheSearch(JointModelDocs docs) {
  const IdentificationOptions search;
  docs.lag_ticks = WithRange(docs.lag_ticks, search.lag_min_ticks, search.lag_max_ticks);
  docs.accel_ticks = WithRange(docs.accel_ticks, search.accel_min_ticks, search.accel_max_ticks);
  return docs;
}

// The constructor's precondition, through the declarations: the keys as declared, but the
// initial model any joint model (an estimate far off) within the search ranges.
void CheckSpec(AdaptiveController::Spec spec, const std::string& prefix) {
  KeyChecker model_checker(prefix + "initial_model.");
  leglab::VisitKeys(model_checker, spec.initial_model, WithinTheSearch(kAnyJointModel));
  spec.initial_model = AdaptiveController::Spec{}.initial_model;  // checked above
  CheckKeys(prefix, spec, &AdaptiveController::VisitKeys);
}

}  // namespace

void AdaptiveController::VisitKeys(KeyVisitor& v, Spec& spec) {
  v.Section("initial_model",
            [&] { leglab::VisitKeys(v, spec.initial_model, WithinTheSearch(kJointModelKeys)); });
  v.Key("window_steps", spec.window_steps,
        {.min = 1, .max = 50, .description = "steps of data each estimate is fitted to"});
  v.Key("probe_deg", spec.probe_deg,
        {.min = 0,
         .max = 45,
         .unit = "deg",
         .description = "pulse added for a joint its window never saturates; 0: no probing"});
  v.Key("probe_ticks", spec.probe_ticks,
        {.min = 0,
         .max = 64,
         .unit = "ticks",
         .description = "how long a probe is held: 0, a pulse of l + a ticks; > 0, a "
                        "step-test-like excursion while the model is uncertain"});
}

AdaptiveController::AdaptiveController(const Spec& spec, const ControllerContext& context)
    : spec_(spec), context_(context) {
  if (context_.desired.empty()) {
    throw std::invalid_argument("controller: the desired cycle is empty");
  }
  CheckSpec(spec_, std::string(kTraits.config_section) + ".");
  pwl_segments_ = std::max(1, context_.ApproximationSegments());
  Reset();
}

void AdaptiveController::Reset() {
  requests_ = context_.desired;  // replaced below; the fallback should a plan fail
  for (int j = 0; j < kLegJoints; ++j) {
    planned_[j] = spec_.initial_model;
    estimates_[j] = {spec_.initial_model, kNoFit};
    Replan(j, spec_.initial_model);
    window_[j] = {};
  }
  last_observed_tick_ = -1;
  probe_next_.fill(false);
  probing_.fill(false);
  vmax_known_.fill(false);
  for (auto& steps : probed_steps_) steps.clear();
  stable_fits_.fill(0);
  learned_.fill(false);
  baseline_rms_.fill(kNoFit);
  probe_sign_.fill(1.0);
  if (Excursions()) {
    probing_.fill(true);  // nothing is known yet: the first step is probed
    for (int j = 0; j < kLegJoints; ++j) probe_sign_[j] = ProbeSign(j);
  }
}

bool AdaptiveController::Excursions() const {
  return spec_.probe_ticks > 0 && spec_.probe_deg > 0.0;
}

double AdaptiveController::ProbeSign(int joint) const {
  // Towards the side with more room over the excursion's ticks, so the limit clamps least.
  const auto period = static_cast<int>(requests_.size());
  const int end = std::min(period, kProbeLeadTicks + spec_.probe_ticks);
  double low = std::numeric_limits<double>::infinity();
  double high = -low;
  for (int t = std::min(kProbeLeadTicks, period - 1); t < end; ++t) {
    low = std::min(low, requests_[t][joint]);
    high = std::max(high, requests_[t][joint]);
  }
  if (!(low <= high)) return 1.0;
  const double lower = RadToDeg(context_.limits[joint].lower_rad);
  const double upper = RadToDeg(context_.limits[joint].upper_rad);
  return upper - high >= low - lower ? 1.0 : -1.0;
}

bool AdaptiveController::Replan(int joint, const JointModelParams& model) {
  const auto period = static_cast<int>(context_.desired.size());
  try {
    std::vector<double> desired(period);
    for (int t = 0; t < period; ++t) desired[t] = context_.desired[t][joint];
    const PiecewiseLinear pwl = FitPiecewiseLinear(desired, model.v_max_deg_per_tick,
                                                   {.segments = std::min(pwl_segments_, period)});
    const std::vector<double> r = SynthesizeRequests(model, pwl, CmMethod::kExact);
    if (!std::all_of(r.begin(), r.end(), [](double v) { return std::isfinite(v); })) return false;
    const double lower = RadToDeg(context_.limits[joint].lower_rad);
    const double upper = RadToDeg(context_.limits[joint].upper_rad);
    for (int t = 0; t < period; ++t) requests_[t][joint] = std::clamp(r[t], lower, upper);
  } catch (const std::exception&) {
    return false;  // the 8 ms loop does not throw: keep the plan it had
  }
  planned_[joint] = model;
  return true;
}

LegAngles AdaptiveController::Update(long tick, const LegAngles& /*measured_deg*/) {
  const auto period = static_cast<long>(requests_.size());
  const long in_step = (tick % period + period) % period;
  LegAngles request = CycleAt(requests_, tick);
  for (int j = 0; j < kLegJoints; ++j) {
    const double lower = RadToDeg(context_.limits[j].lower_rad);
    const double upper = RadToDeg(context_.limits[j].upper_rad);
    if (probing_[j] && Excursions()) {
      if (in_step >= kProbeLeadTicks && in_step < kProbeLeadTicks + spec_.probe_ticks) {
        request[j] += probe_sign_[j] * spec_.probe_deg;
      }
    } else if (probing_[j] && in_step < planned_[j].lag_ticks + planned_[j].accel_ticks) {
      // Away from the nearer limit, so the pulse is not clamped away.
      request[j] += upper - request[j] >= request[j] - lower ? spec_.probe_deg : -spec_.probe_deg;
    }
    if (!std::isfinite(request[j])) request[j] = CycleAt(context_.desired, tick)[j];
    request[j] = std::clamp(request[j], lower, upper);
  }
  return request;
}

void AdaptiveController::Observe(long tick, const LegAngles& applied_deg,
                                 const LegAngles& measured_deg) {
  // The estimator fits consecutive ticks: a gap starts the window afresh.
  const bool consecutive = tick == last_observed_tick_ + 1;
  last_observed_tick_ = tick;
  const size_t capacity = static_cast<size_t>(spec_.window_steps) * context_.desired.size();
  for (int j = 0; j < kLegJoints; ++j) {
    JointRecording& w = window_[j];
    if (!consecutive) w = {};
    w.request_deg.push_back(applied_deg[j]);
    w.measured_deg.push_back(measured_deg[j]);
    if (w.request_deg.size() > capacity) {
      const auto excess = static_cast<long>(w.request_deg.size() - capacity);
      w.request_deg.erase(w.request_deg.begin(), w.request_deg.begin() + excess);
      w.measured_deg.erase(w.measured_deg.begin(), w.measured_deg.begin() + excess);
    }
  }
}

void AdaptiveController::LearnFromExcursions(int joint, JointRecording step) {
  const int j = joint;
  if (!learned_[j]) {
    if (probing_[j]) {
      probed_steps_[j].push_back(std::move(step));
      if (probed_steps_[j].size() > static_cast<size_t>(kPooledProbeSteps)) {
        probed_steps_[j].erase(probed_steps_[j].begin());
      }
    }
    if (probed_steps_[j].empty()) return;
    IdentificationResult fit;
    try {
      fit = IdentifyJointModel(probed_steps_[j], IdentificationOptions{});
    } catch (const std::exception&) {
      return;  // e.g. a non-finite sample: keep the estimate, probe again
    }
    const JointModelParams& before = estimates_[j].params;
    const bool kept = probed_steps_[j].size() >= 2 && fit.params.lag_ticks == before.lag_ticks &&
                      fit.params.accel_ticks == before.accel_ticks;
    stable_fits_[j] = kept ? stable_fits_[j] + 1 : 0;
    estimates_[j] = fit;
    if (stable_fits_[j] >= kStableFits) {
      learned_[j] = true;
      baseline_rms_[j] = kNoFit;
    }
    return;
  }
  // Learned: the walk monitors the model.
  const JointModelParams& p = estimates_[j].params;
  double rms = kNoFit;
  try {
    const int warmup = p.lag_ticks + p.accel_ticks;
    const std::vector<double> predicted = PredictRecording(p, step, warmup);
    double sum = 0.0;
    const auto n = static_cast<long>(step.measured_deg.size());
    for (long t = warmup; t < n; ++t) {
      const double e = step.measured_deg[t] - predicted[t];
      sum += e * e;
    }
    rms = n > warmup ? std::sqrt(sum / static_cast<double>(n - warmup)) : kNoFit;
  } catch (const std::exception&) {
    return;
  }
  if (!std::isfinite(rms)) return;
  estimates_[j].rms_residual_deg = rms;
  if (!std::isfinite(baseline_rms_[j])) {
    baseline_rms_[j] = rms;
  } else if (rms > kChangeRatio * std::max(baseline_rms_[j], kResidualFloorDeg)) {
    learned_[j] = false;  // the joint changed: learn it again, from new probed steps only
    probed_steps_[j].clear();
    stable_fits_[j] = 0;
  }
}

void AdaptiveController::EndOfStep(long /*step*/) {
  if (Excursions()) {
    const size_t period = context_.desired.size();
    for (int j = 0; j < kLegJoints; ++j) {
      const JointRecording& w = window_[j];
      if (w.request_deg.size() >= period) {
        const auto from = static_cast<long>(w.request_deg.size() - period);
        LearnFromExcursions(j, {{w.request_deg.begin() + from, w.request_deg.end()},
                                {w.measured_deg.begin() + from, w.measured_deg.end()}});
      }
      const JointModelParams& now = estimates_[j].params;
      const JointModelParams& planned = planned_[j];
      if (now.lag_ticks != planned.lag_ticks || now.accel_ticks != planned.accel_ticks ||
          std::abs(now.v_max_deg_per_tick - planned.v_max_deg_per_tick) > kVmaxResolution ||
          std::abs(now.theta0_deg - planned.theta0_deg) > kTheta0Resolution) {
        Replan(j, now);
      }
      probing_[j] = !learned_[j];
      probe_sign_[j] = ProbeSign(j);
    }
    return;
  }
  probing_.fill(false);
  for (int j = 0; j < kLegJoints; ++j) {
    // A whole step at least: shorter windows do not cover a walk's motion.
    if (window_[j].request_deg.size() < context_.desired.size()) continue;
    WindowEstimate estimate;
    try {
      estimate = EstimateJointModelInWindow(window_[j], estimates_[j].params);
    } catch (const std::exception&) {
      continue;  // e.g. a joint that did not move, or a non-finite sample: keep the estimate
    }
    const JointModelParams& now = estimate.fit.params;
    const JointModelParams& before = estimates_[j].params;
    // A new lag or acceleration time means the joint changed: its v_max is known no longer.
    if (now.lag_ticks != before.lag_ticks || now.accel_ticks != before.accel_ticks) {
      vmax_known_[j] = false;
    }
    if (estimate.v_max_identified) vmax_known_[j] = true;
    probe_next_[j] = spec_.probe_deg > 0.0 && !vmax_known_[j];
    estimates_[j] = estimate.fit;

    const JointModelParams& planned = planned_[j];
    if (now.lag_ticks != planned.lag_ticks || now.accel_ticks != planned.accel_ticks ||
        std::abs(now.v_max_deg_per_tick - planned.v_max_deg_per_tick) > kVmaxResolution ||
        std::abs(now.theta0_deg - planned.theta0_deg) > kTheta0Resolution) {
      Replan(j, now);
    }
  }
  probing_ = probe_next_;
}

}  // namespace leglab
