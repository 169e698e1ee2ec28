#include "leglab/servo/servo_planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "horizon_descent.h"
#include "leglab/core/format.h"
#include "servo_plan_steps.h"

namespace leglab {
namespace {

using servo_plan::Choice;
using servo_plan::DesiredPathTick;
using servo_plan::ExtendedStepper;
using servo_plan::HorizonError;
using servo_plan::HorizonGradient;
using servo_plan::InvertAtPending;
using servo_plan::InvertExtendedTick;
using servo_plan::PaperStepper;
using servo_plan::PathStep;

// The state at rest at `angle_deg`, in place (no allocation): as ServoRestState / RestState.
void ResetInPlace(ServoModelState& state, double angle_deg) {
  state.angle_deg = angle_deg;
  state.velocity_deg_s = 0.0;
  std::fill(state.past_requests_deg.begin(), state.past_requests_deg.end(), angle_deg);
}
void ResetInPlace(JointModelState& state, double angle_deg) {
  state.angle_deg = angle_deg;
  std::fill(state.past_requests_deg.begin(), state.past_requests_deg.end(), angle_deg);
}

}  // namespace

struct ServoPlanner::Impl {
  virtual ~Impl() = default;
  virtual int Horizon() const = 0;
  virtual int Preview() const = 0;
  virtual void Reset(double angle_deg) = 0;
  virtual double Request(std::span<const double> window_deg, double measured_deg) = 0;
  virtual void Hold(std::span<const double> window_deg) = 0;
  virtual double Predicted() const = 0;
  virtual double Expected() const = 0;
  virtual bool Reanchored() const = 0;
  virtual long Ticks() const = 0;
};

namespace {

template <class Params>
class Planner final : public ServoPlanner::Impl {
 public:
  using Stepper =
      std::conditional_t<std::is_same_v<Params, ServoModelParams>, ExtendedStepper, PaperStepper>;
  using State = typename Stepper::State;
  static constexpr bool kExtended = std::is_same_v<Params, ServoModelParams>;

  Planner(const Params& params, const ServoDrive& drive, double tick_s, const ServoLimits& limits,
          const ServoPlannerOptions& options)
      : params_(params),
        drive_(drive),
        tick_s_(tick_s),
        limits_(limits),
        max_step_deg_(limits.max_speed_deg_s * tick_s),
        options_(options),
        horizon_(params.lag_ticks + 1) {
    handover_ = options.handover_ticks >= 0 ? options.handover_ticks : DefaultHandover();
    preview_ =
        options.preview_ticks >= 0 ? options.preview_ticks
        : options.method == PlanMethod::kOptimal
            ? std::min(params.lag_ticks + handover_ + kOptimalWindowTicks, kMaxServoPreviewTicks)
            : horizon_;
    if (options.method == PlanMethod::kOptimal && preview_ <= params.lag_ticks) {
      throw std::invalid_argument("servo planner: preview_ticks " + std::to_string(preview_) +
                                  " is too short for the optimal method: it needs more than the "
                                  "model's lag (" +
                                  std::to_string(params.lag_ticks) + " ticks)");
    }
    budget_s_ = options.budget_s < 0.0 ? tick_s / 2.0 : options.budget_s;
    const int hold = options.method == PlanMethod::kOptimal ? options.hold_ticks : 0;
    desired_.assign(static_cast<size_t>(std::max(preview_, horizon_) + hold) + 1, 0.0);
    anchored_ = stepper().Rest(0.0);
    scratch_ = anchored_;
    if (options.method == PlanMethod::kOptimal) {
      // R(t..t+preview+hold-l-1): the last acts on M(t+preview+hold).
      const auto decisions = static_cast<size_t>(preview_ + hold - params.lag_ticks);
      plan_.assign(decisions, 0.0);
      challenger_.assign(decisions, 0.0);
      model_based_.assign(decisions, 0.0);
      model_based_state_ = anchored_;
      for (servo_plan::HorizonDescent<Stepper>* descent : {&descent_, &challenger_descent_}) {
        descent->Reserve(decisions, static_cast<size_t>(preview_) + static_cast<size_t>(hold),
                         anchored_);
      }
      // The requests that act on the preview's last handover_ ticks, and on the held ones, are
      // model_based's.
      free_ = decisions - std::min(decisions, static_cast<size_t>(handover_ + hold));
    }
  }

  int Horizon() const override { return horizon_; }
  int Preview() const override { return preview_; }
  double Predicted() const override { return predicted_; }
  double Expected() const override { return anchored_.angle_deg; }
  bool Reanchored() const override { return reanchored_; }
  long Ticks() const override { return ticks_; }

  void Reset(double angle_deg) override {
    if (!(angle_deg >= limits_.min_deg && angle_deg <= limits_.max_deg)) {
      throw std::invalid_argument("servo planner: the reset angle " + FormatNumber(angle_deg) +
                                  " deg is outside the limits [" + FormatNumber(limits_.min_deg) +
                                  ", " + FormatNumber(limits_.max_deg) + "]");
    }
    ResetInPlace(anchored_, angle_deg);
    stepper().Advance(anchored_);
    previous_ = angle_deg;
    has_measured_ = false;
    started_ = true;
    ticks_ = 0;
    predicted_ = angle_deg;
    reanchored_ = false;
  }

  double Request(std::span<const double> window_deg, double measured_deg) override {
    CheckWindow(window_deg);
    if (const std::string problem = KeyValueProblem(measured_deg, kServoAngleDoc);
        !problem.empty()) {
      throw std::invalid_argument("servo planner: the measured angle must be " + problem +
                                  ", got " + FormatNumber(measured_deg));
    }
    TakeWindow(window_deg);
    Anchor(measured_deg);

    const double request =
        options_.method == PlanMethod::kOptimal ? OptimalRequest() : ModelBasedRequest();
    Stepper::Push(anchored_, request);
    stepper().Advance(anchored_);
    previous_ = request;
    last_desired_ = desired_[0];
    last_measured_ = measured_deg;
    has_measured_ = true;
    ++ticks_;
    return request;
  }

  void Hold(std::span<const double> window_deg) override {
    CheckWindow(window_deg);
    TakeWindow(window_deg);
    // The servo kept R(t-1) for this tick: the model copy is driven by it, and optimal's
    // receding plan gives up its first request, as a Request's would.
    if (options_.method == PlanMethod::kOptimal) {
      if (ticks_ == 0) FirstPlan();
      ShiftPlan();
    }
    Stepper::Push(anchored_, previous_);
    stepper().Advance(anchored_);
    last_desired_ = desired_[0];
    has_measured_ = false;  // no measurement this tick: the next one gives no velocity
    reanchored_ = false;
    ++ticks_;
  }

 private:
  // Throws std::invalid_argument, the planner unchanged, on an empty window or a desired angle
  // beyond its range among those used.
  void CheckWindow(std::span<const double> window_deg) const {
    if (window_deg.empty()) {
      throw std::invalid_argument("servo planner: the window holds no desired angle");
    }
    const size_t used = std::min(window_deg.size(), static_cast<size_t>(preview_) + 1);
    for (size_t j = 0; j < used; ++j) {
      if (const std::string problem = KeyValueProblem(window_deg[j], kServoAngleDoc);
          !problem.empty()) {
        throw std::invalid_argument("servo planner: desired angle " + std::to_string(j) +
                                    " of the window must be " + problem + ", got " +
                                    FormatNumber(window_deg[j]));
      }
    }
  }

  // D(t + j) for j = 0..preview, the window's last angle held beyond it (a checked window).
  void TakeWindow(std::span<const double> window_deg) {
    if (!started_) Reset(window_deg[0]);
    const size_t used = std::min(window_deg.size(), static_cast<size_t>(preview_) + 1);
    for (size_t j = 0; j < desired_.size(); ++j) desired_[j] = window_deg[std::min(j, used - 1)];
    if (ticks_ == 0) last_desired_ = desired_[0];
  }

  // optimal's plan at tick 0: model_based's, nothing learnt carried from before a Reset.
  void FirstPlan() {
    ModelBasedPlan(plan_);
    descent_.ForgetMemory();
    restart_challenger_ = true;
  }

  // optimal's plans one tick on: R(t+1..) to the front, the last request held (the next
  // Request replaces the plans' ends with model_based's), their curvature pairs likewise.
  void ShiftPlan() {
    std::copy(plan_.begin() + 1, plan_.end(), plan_.begin());
    std::copy(challenger_.begin() + 1, challenger_.end(), challenger_.begin());
    descent_.ShiftMemory(free_);
    challenger_descent_.ShiftMemory(free_);
  }

  // ServoPlannerOptions::handover_ticks' default: two horizons and the model's settling, three
  // velocity time constants (5 % left) for the extended model, the averaging window a (all of
  // it) for the paper's.
  int DefaultHandover() const {
    if constexpr (kExtended) {
      const double settle = std::ceil(3.0 * params_.velocity_lag_s / tick_s_);
      return 2 * horizon_ + static_cast<int>(std::min(settle, double{kMaxServoPreviewTicks}));
    } else {
      return 2 * horizon_ + params_.accel_ticks;
    }
  }

  Stepper stepper() const {
    if constexpr (kExtended) {
      return ExtendedStepper{params_, drive_, tick_s_};
    } else {
      return PaperStepper{params_};
    }
  }

  // D(t + j), j >= -1 (D(t - 1): the last tick's, or D(0) at tick 0, as the batch plan's).
  double D(int j) const { return j < 0 ? last_desired_ : desired_[static_cast<size_t>(j)]; }

  // The measurement against the model copy's M(t): beyond reanchor_deg the copy moves to it.
  void Anchor(double measured_deg) {
    predicted_ = anchored_.angle_deg;
    reanchored_ = std::abs(measured_deg - predicted_) > options_.reanchor_deg;
    if (!reanchored_) return;
    anchored_.angle_deg = measured_deg;
    if constexpr (kExtended) {
      if (has_measured_) anchored_.velocity_deg_s = (measured_deg - last_measured_) / tick_s_;
    }
  }

  double Clamp(double request, double previous) const {
    request = std::clamp(request, previous - max_step_deg_, previous + max_step_deg_);
    return std::clamp(request, limits_.min_deg, limits_.max_deg);
  }

  double ModelBasedRequest() {
    const int lag = params_.lag_ticks;
    if constexpr (kExtended) {
      // The batch plan's request (DesiredPathRequests): open loop along the desired path.
      const PathStep step = DesiredPathTick(stepper(), D(lag - 1), D(lag), D(lag + 1));
      return Clamp(step.request_deg, previous_);
    } else {
      // The batch plan's inversion, from the model's state (re-anchored when measured off it).
      const double lo = std::max(limits_.min_deg, previous_ - max_step_deg_);
      const double hi = std::min(limits_.max_deg, previous_ + max_step_deg_);
      return InvertAtPending(stepper(), anchored_, scratch_, previous_, lo, hi, D(lag + 1))
          .request_deg;
    }
  }

  // D(t..t+preview).
  // optimal's D(t..t+preview+hold_ticks), the last known angle held beyond the window.
  std::span<const double> Desired() const { return desired_; }

  // model_based's requests R(t..t+m-1) for the horizon from the model copy, within the limits:
  // those online model_based would send, were the servo the model.
  void ModelBasedPlan(std::vector<double>& plan) {
    const int lag = params_.lag_ticks;
    double previous = previous_;
    if constexpr (kExtended) {
      for (size_t i = 0; i < plan.size(); ++i) {
        const int q = static_cast<int>(i) + lag;
        plan[i] = previous =
            Clamp(DesiredPathTick(stepper(), D(q - 1), D(q), D(q + 1)).request_deg, previous);
      }
    } else {
      model_based_state_ = anchored_;
      for (size_t i = 0; i < plan.size(); ++i) {
        const double lo = std::max(limits_.min_deg, previous - max_step_deg_);
        const double hi = std::min(limits_.max_deg, previous + max_step_deg_);
        plan[i] = previous = InvertAtPending(stepper(), model_based_state_, scratch_, previous, lo,
                                             hi, D(static_cast<int>(i) + lag + 1))
                                 .request_deg;
        Stepper::Push(model_based_state_, previous);
        stepper().Advance(model_based_state_);
      }
    }
  }

  // kOptimal: the incumbent descends from the better, by the horizon's error, of model_based's
  // plan and its own last plan shifted by one tick (its end model_based's, its curvature pairs
  // shifted likewise), for the tick's iterations or budget. Once it stalls, the challenger
  // spends what is left: a descent from model_based's plan afresh, carried across ticks the
  // same way until it stalls; a challenger below the incumbent becomes it. The incumbent's
  // first request is sent. A warm start can settle in a worse basin than the one model_based's
  // plan descends into, and only a fresh start finds the other. Never worse than model_based
  // on the horizon: both start there or lower, and only descend.
  double OptimalRequest() {
    const auto start = std::chrono::steady_clock::now();
    ModelBasedPlan(model_based_);
    bool fresh = ticks_ == 0;  // the incumbent starts from model_based's plan, memory forgotten
    if (!fresh) {
      ShiftOnto(plan_, descent_);
      fresh = Error(model_based_) <= Error(plan_);
    }
    if (fresh) {
      std::copy(model_based_.begin(), model_based_.end(), plan_.begin());
      descent_.ForgetMemory();
    }
    if (ticks_ == 0) restart_challenger_ = true;
    // The incumbent spends the tick; once it stalls, the challenger spends what is left.
    const int cap = options_.optimal_iterations_per_tick;
    servo_plan::DescentStop stop{.max_iterations = cap};
    if (budget_s_ > 0.0) {
      stop.deadline = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                  std::chrono::duration<double>(budget_s_));
    }
    const servo_plan::DescentResult incumbent =
        descent_.Descend(stepper(), anchored_, Desired(), Bounds(), plan_, free_, stop);
    // A challenger starting afresh would repeat the incumbent's descent step for step.
    if (free_ == 0 || (fresh && restart_challenger_)) return plan_[0];
    if (restart_challenger_) {
      std::copy(model_based_.begin(), model_based_.end(), challenger_.begin());
      challenger_descent_.ForgetMemory();
      restart_challenger_ = false;
    } else {
      ShiftOnto(challenger_, challenger_descent_);
    }
    stop.max_iterations = cap - incumbent.iterations;
    if (!incumbent.stalled || stop.max_iterations == 0 ||
        (stop.deadline && std::chrono::steady_clock::now() >= *stop.deadline)) {
      return plan_[0];
    }
    const servo_plan::DescentResult challenger = challenger_descent_.Descend(
        stepper(), anchored_, Desired(), Bounds(), challenger_, free_, stop);
    restart_challenger_ = challenger.stalled;
    if (challenger.error < incumbent.error) {
      plan_.swap(challenger_);
      std::swap(descent_, challenger_descent_);
      restart_challenger_ = true;
    }
    return plan_[0];
  }

  // `plan` one tick on: its free requests moved one earlier, the rest (and the last, if every
  // request is free) model_based's for this tick, projected; the descent's curvature pairs
  // shifted with it.
  void ShiftOnto(std::vector<double>& plan, servo_plan::HorizonDescent<Stepper>& descent) {
    const auto kept = static_cast<long>(std::min(free_, plan.size() - 1));
    std::copy(plan.begin() + 1, plan.begin() + kept + 1, plan.begin());
    std::copy(model_based_.begin() + kept, model_based_.end(), plan.begin() + kept);
    servo_plan::ProjectRequests(Bounds(), plan);
    descent.ShiftMemory(free_);
  }

  servo_plan::RequestBounds Bounds() const {
    return {limits_.min_deg, limits_.max_deg, max_step_deg_, previous_};
  }

  double Error(const std::vector<double>& plan) {
    return HorizonError(stepper(), anchored_, scratch_, plan, Desired(), {});
  }

  Params params_;
  ServoDrive drive_;
  double tick_s_;
  ServoLimits limits_;
  double max_step_deg_;
  ServoPlannerOptions options_;
  int horizon_;
  int preview_ = 0;

  State anchored_;  // the model copy the requests drive, re-anchored on measurements
  State scratch_;
  double previous_ = 0.0;        // R(t-1)
  std::vector<double> desired_;  // D(t..t+max(preview, horizon))
  double last_desired_ = 0.0;    // D(t-1)
  double last_measured_ = 0.0;
  bool has_measured_ = false;
  bool started_ = false;
  long ticks_ = 0;
  double predicted_ = 0.0;
  bool reanchored_ = false;

  // kOptimal's receding horizon: R(t..t+preview-l-1), model_based's for it, and the optimiser.
  std::vector<double> plan_;
  std::vector<double> model_based_;
  State model_based_state_;
  servo_plan::HorizonDescent<Stepper> descent_;
  // The challenger's plan and optimiser, and whether it starts afresh next tick.
  std::vector<double> challenger_;
  servo_plan::HorizonDescent<Stepper> challenger_descent_;
  bool restart_challenger_ = true;
  int handover_ = 0;
  size_t free_ = 0;  // the plan's requests that descend; the rest are model_based's
  double budget_s_ = 0.0;
};

}  // namespace

void VisitKeys(KeyVisitor& v, ServoPlannerOptions& options) {
  v.Key("preview_ticks", options.preview_ticks, kServoPreviewDoc);
  v.Key("reanchor_deg", options.reanchor_deg,
        {.min = 0,
         .max = std::numeric_limits<double>::infinity(),
         .min_open = true,
         .unit = "deg",
         .description = "a measurement this far off the model's prediction re-anchors the "
                        "model (inf: never)"});
  v.Key("optimal_iterations_per_tick", options.optimal_iterations_per_tick, kServoIterationsDoc);
  v.Key("budget_s", options.budget_s, kServoBudgetDoc);
  v.Key("hold_ticks", options.hold_ticks, kServoHoldDoc);
  v.Key("handover_ticks", options.handover_ticks, kServoHandoverDoc);
}

namespace {

void CheckLag(int ticks) {
  if (ticks > kMaxServoLagTicks) {
    throw std::invalid_argument(
        "servo planner: a model's lag (or averaging window) must be at "
        "most " +
        std::to_string(kMaxServoLagTicks) + " ticks, got " + std::to_string(ticks));
  }
}

void CheckPlannerInputs(const ServoLimits& limits, const ServoPlannerOptions& options) {
  if (std::string problem = ServoLimitsProblem(limits); !problem.empty()) {
    throw std::invalid_argument("servo planner: " + problem);
  }
  const std::string problem =
      KeysProblem(options, [](KeyVisitor& v, ServoPlannerOptions& o) { VisitKeys(v, o); });
  if (!problem.empty()) throw std::invalid_argument("servo planner: " + problem);
}

}  // namespace

ServoPlanner::ServoPlanner(const ServoModelParams& params, const ServoDrive& drive, double tick_s,
                           const ServoLimits& limits, const ServoPlannerOptions& options) {
  const std::string problem = ServoPlanProblem(params, drive, tick_s);
  if (!problem.empty()) throw std::invalid_argument("servo planner: " + problem);
  CheckLag(params.lag_ticks);
  CheckPlannerInputs(limits, options);
  impl_ = std::make_unique<Planner<ServoModelParams>>(params, drive, tick_s, limits, options);
}

ServoPlanner::ServoPlanner(const JointModelParams& params, double tick_s, const ServoLimits& limits,
                           const ServoPlannerOptions& options) {
  const std::string problem = JointModelPlanProblem(params, tick_s);
  if (!problem.empty()) throw std::invalid_argument("servo planner: " + problem);
  CheckLag(params.lag_ticks);
  CheckLag(params.accel_ticks);
  CheckPlannerInputs(limits, options);
  impl_ =
      std::make_unique<Planner<JointModelParams>>(params, ServoDrive{}, tick_s, limits, options);
}

ServoPlanner::ServoPlanner(ServoPlanner&&) noexcept = default;
ServoPlanner& ServoPlanner::operator=(ServoPlanner&&) noexcept = default;
ServoPlanner::~ServoPlanner() = default;

int ServoPlanner::HorizonTicks() const { return impl_->Horizon(); }
int ServoPlanner::PreviewTicks() const { return impl_->Preview(); }
void ServoPlanner::Reset(double angle_deg) { impl_->Reset(angle_deg); }
double ServoPlanner::Request(std::span<const double> window_deg, double measured_deg) {
  return impl_->Request(window_deg, measured_deg);
}
void ServoPlanner::Hold(std::span<const double> window_deg) { impl_->Hold(window_deg); }
double ServoPlanner::PredictedDeg() const { return impl_->Predicted(); }
double ServoPlanner::ExpectedDeg() const { return impl_->Expected(); }
bool ServoPlanner::Reanchored() const { return impl_->Reanchored(); }
long ServoPlanner::Ticks() const { return impl_->Ticks(); }

}  // namespace leglab
