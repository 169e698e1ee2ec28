#pragma once

// The optimiser of the optimal plans: projected limited-memory BFGS on a plan's squared error
// from a pending model state (HorizonError), with its exact gradient (HorizonGradient). The
// batch plan (servo_plan.cc) runs it over blocks of the whole motion, the online planner
// (servo_planner.cc) over its preview each tick; every buffer is sized once, so that a tick
// allocates nothing. Internal to leglab::servo.

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <optional>
#include <span>
#include <vector>

#include "servo_plan_steps.h"

namespace leglab::servo_plan {

/// Where a plan's requests must stay: within [min_deg, max_deg], each at most max_step_deg
/// from the one before it, the first from `previous_deg` (R(t-1)).
struct RequestBounds {
  double min_deg = 0.0;
  double max_deg = 0.0;
  double max_step_deg = 0.0;
  double previous_deg = 0.0;
};

/// The requests clamped in time order to the speed limit, then to the limits.
inline void ProjectRequests(const RequestBounds& b, std::span<double> plan) {
  double previous = b.previous_deg;
  for (double& r : plan) {
    r = std::clamp(r, previous - b.max_step_deg, previous + b.max_step_deg);
    r = std::clamp(r, b.min_deg, b.max_deg);
    previous = r;
  }
}

/// When a descent stops, besides when no step lowers the error or an iteration gains at most
/// 1e-12 of it: after `max_iterations`, or once `deadline` has passed (checked before each
/// iteration and each try of its line search).
struct DescentStop {
  int max_iterations = 0;
  std::optional<std::chrono::steady_clock::time_point> deadline;
};

struct DescentResult {
  double error = 0.0;    ///< the plan's HorizonError on return
  int iterations = 0;    ///< iterations that lowered it
  bool stalled = false;  ///< stopped because no step lowered the error, not by `stop`
};

/// Projected L-BFGS (Nocedal and Wright, algorithm 7.4, memory kMemory) on HorizonError, its
/// directions projected onto those the constraints allow (ProjectOntoCone): a request at the
/// speed limit from the one before it, pressed beyond it, moves with that one, so that a ramp
/// at the limit moves as a whole. Each iteration tries, until one lowers the error: the
/// quasi-Newton step; the steepest descent, scaled so that no request moves more than 1 deg;
/// the steepest descent in the increments R(i) - R(i-1) (IncrementDirection), scaled alike.
/// Each is projected (ProjectRequests) and halved until the error falls (at most 40 times). An
/// iteration that gains next to nothing starts the next from the direction after the one it
/// took, and a stall is when none is left. Only steps that lower the error are taken, so the
/// plan returned is never worse than the one given. Where no position limit binds and no held
/// request is clamped by the free ones, a stall is a stationary point of the constrained
/// problem in the increments (AStalledHorizonDescentIsStationaryInTheIncrements).
template <class Stepper>
class HorizonDescent {
 public:
  using State = typename Stepper::State;
  static constexpr size_t kMemory = 8;

  /// Buffers for plans of up to `decisions` requests over up to `preview` + 1 desired angles,
  /// from states shaped like `like` (the only allocation).
  void Reserve(size_t decisions, size_t preview, const State& like) {
    for (std::vector<double>* v :
         {&candidate_, &gradient_, &next_gradient_, &direction_, &held_, &full_gradient_}) {
      v->assign(decisions, 0.0);
    }
    runs_.assign(decisions, Run{});
    steps_.assign(kRows * decisions, 0.0);
    changes_.assign(kRows * decisions, 0.0);
    angles_.assign(preview + 1, 0.0);
    candidate_angles_.assign(preview + 1, 0.0);
    scratch_ = like;
    decisions_ = decisions;
  }

  /// Forgets the curvature pairs (a new problem).
  void ForgetMemory() { count_ = 0; }

  /// The curvature pairs moved one request earlier (each pair's first dropped, a 0 after its
  /// last), for a receding horizon's next tick: its plan is the last one shifted likewise.
  /// Forgotten if a shifted pair's curvature is no longer positive.
  void ShiftMemory(size_t free) {
    if (free == 0) count_ = 0;
    for (size_t k = 0; k < count_; ++k) {
      double* step = &steps_[((first_ + k) % kRows) * decisions_];
      double* change = &changes_[((first_ + k) % kRows) * decisions_];
      double curvature = 0.0;
      for (double* row : {step, change}) {
        std::copy(row + 1, row + free, row);
        row[free - 1] = 0.0;
      }
      for (size_t i = 0; i < free; ++i) curvature += step[i] * change[i];
      if (!(curvature > 0.0)) {
        count_ = 0;
        return;
      }
    }
  }

  /// Lowers the HorizonError of `plan` (R(t..t+m-1), m <= the reserved decisions) from
  /// `pending` over `desired` (D(t..t+P), P + 1 <= the reserved preview + 1): its first `free`
  /// requests move, the others are held at the values they have on entry (re-projected after
  /// each move of those before them). `plan` is projected on entry.
  DescentResult Descend(const Stepper& stepper, const State& pending,
                        std::span<const double> desired, const RequestBounds& bounds,
                        std::span<double> plan, size_t free, const DescentStop& stop) {
    const size_t n = plan.size();
    free = std::min(free, n);
    std::copy(plan.begin(), plan.end(), held_.begin());
    ProjectRequests(bounds, plan);
    const std::span<double> candidate(candidate_.data(), n);
    const size_t p = desired.size();
    DescentResult result;
    result.error = HorizonError(stepper, pending, scratch_, plan, desired, {angles_.data(), p});
    if (free == 0) {
      result.stalled = true;
      return result;
    }
    Gradient(stepper, pending, plan, desired, free, gradient_);
    // Tries plan + alpha direction, projected, halving alpha; true once the error falls.
    // A deadline passed mid-search abandons it, so that an iteration overruns the budget by at
    // most one evaluation and the gradient of the step it takes.
    bool late = false;
    const auto search = [&](double alpha) {
      for (int tries = 0; tries < 40; ++tries, alpha /= 2) {
        if (stop.deadline && std::chrono::steady_clock::now() >= *stop.deadline) {
          late = true;
          return false;
        }
        for (size_t i = 0; i < free; ++i) candidate[i] = plan[i] + alpha * direction_[i];
        std::copy(held_.begin() + static_cast<long>(free), held_.begin() + static_cast<long>(n),
                  candidate.begin() + static_cast<long>(free));
        ProjectRequests(bounds, candidate);
        const double error = HorizonError(stepper, pending, scratch_, candidate, desired,
                                          {candidate_angles_.data(), p}, result.error);
        if (error < result.error) {
          result.error = error;
          return true;
        }
      }
      return false;
    };
    // The directions, each tried when the one before it fails, and first for the next iteration
    // after the one before it gained next to nothing (cut short by the constraints).
    Direction first = Direction::kQuasiNewton;
    for (int i = 0; i < stop.max_iterations; ++i) {
      if (stop.deadline && std::chrono::steady_clock::now() >= *stop.deadline) break;
      const double before = result.error;
      Direction used = Direction::kQuasiNewton;
      bool moved = false;
      if (first == Direction::kQuasiNewton && count_ > 0 &&
          QuasiNewtonDirection(bounds, plan, free)) {
        moved = search(1.0);
      }
      if (!moved && !late && first != Direction::kIncrements) {
        count_ = 0;
        used = Direction::kSteepest;
        if (SteepestDirection(bounds, plan, free)) moved = search(1.0);
      }
      if (!moved && !late) {
        count_ = 0;
        used = Direction::kIncrements;
        if (IncrementDirection(bounds, plan, free)) moved = search(1.0);
      }
      if (!moved) {
        result.stalled = !late;
        break;
      }
      ++result.iterations;
      angles_.swap(candidate_angles_);  // the accepted candidate's angles, for its gradient
      Gradient(stepper, pending, candidate, desired, free, next_gradient_);
      // The step and the gradient's change, into the row after the memory's newest pair.
      const size_t slot = (first_ + count_) % kRows;
      double* step = &steps_[slot * decisions_];
      double* change = &changes_[slot * decisions_];
      double curvature = 0.0;
      for (size_t k = 0; k < free; ++k) {
        step[k] = candidate[k] - plan[k];
        change[k] = next_gradient_[k] - gradient_[k];
        curvature += step[k] * change[k];
      }
      std::copy(candidate.begin(), candidate.end(), plan.begin());
      gradient_.swap(next_gradient_);
      // Only pairs of positive curvature keep H positive definite.
      if (curvature > 0.0) {
        if (count_ < kMemory) {
          ++count_;
        } else {
          first_ = (first_ + 1) % kRows;
        }
      }
      // A step that gains next to nothing was cut short by the constraints: the next iteration
      // starts from the direction after it. The increments' gaining so little is a stall.
      if (before - result.error > 1e-12 * before) {
        first = Direction::kQuasiNewton;
      } else if (used == Direction::kIncrements) {
        result.stalled = true;
        break;
      } else {
        first = used == Direction::kQuasiNewton ? Direction::kSteepest : Direction::kIncrements;
      }
    }
    return result;
  }

 private:
  enum class Direction { kQuasiNewton, kSteepest, kIncrements };

  // d HorizonError / d R for the first `free` requests of `plan` into `gradient`, from the
  // angles its HorizonError recorded in angles_.
  void Gradient(const Stepper& stepper, const State& pending, std::span<const double> plan,
                std::span<const double> desired, size_t free, std::vector<double>& gradient) {
    const std::span<const double> angles(angles_.data(), desired.size());
    const std::span<double> full(full_gradient_.data(), plan.size());
    HorizonGradient(stepper, pending, plan, desired, angles, full);
    std::copy(full.begin(), full.begin() + static_cast<long>(free), gradient.begin());
  }

  // x replaced by a move the constraints allow at `plan` (the tangent cone's): a request at the
  // speed limit from the one before it may not move further beyond it (x(i) - x(i-1) >= 0 at
  // -max_step_deg, <= 0 at +max_step_deg; x(-1) = 0 for R(t-1)), nor a request at a limit
  // beyond it. The constraints form a path, and runs of requests that would break one between
  // them are pooled left to right, as the pool-adjacent-violators algorithm pools them, each
  // run moving by its mean, or not at all if it would break one to R(t-1) or a limit. Where
  // the constraints along a run all point one way this is the cone's projection; otherwise it
  // may pool more than the projection would (IncrementDirection then finds the move).
  void ProjectOntoCone(const RequestBounds& b, std::span<const double> plan, double* x,
                       size_t free) {
    const double tie = b.max_step_deg * (1.0 - 1e-9);
    // Whether a run starting at `first`, moving by `value`, breaks the constraint to the one
    // before it, moving by `before`.
    const auto breaks = [&](size_t first, double before, double value) {
      const double step = plan[first] - (first == 0 ? b.previous_deg : plan[first - 1]);
      return (step <= -tie && value < before) || (step >= tie && value > before);
    };
    size_t runs = 0;
    for (size_t i = 0; i < free; ++i) {
      runs_[runs] = {.first = i,
                     .size = 1,
                     .sum = x[i],
                     .at_max = plan[i] >= b.max_deg,
                     .at_min = plan[i] <= b.min_deg,
                     .held = false};
      ++runs;
      while (true) {
        Run& run = runs_[runs - 1];
        if (runs == 1) {
          if (run.held || !breaks(run.first, 0.0, run.Value())) break;
          run.held = true;  // by R(t-1)
          continue;
        }
        Run& before = runs_[runs - 2];
        if (!breaks(run.first, before.Value(), run.Value())) break;
        before.size += run.size;
        before.sum += run.sum;
        before.at_max = before.at_max || run.at_max;
        before.at_min = before.at_min || run.at_min;
        before.held = before.held || run.held;
        --runs;
      }
    }
    for (size_t k = 0; k < runs; ++k) {
      std::fill(x + runs_[k].first, x + runs_[k].first + runs_[k].size, runs_[k].Value());
    }
  }

  // direction_ = the steepest descent projected onto the cone, scaled so that the requests
  // move by at most 1 deg. False if it is 0 (the plan is stationary).
  bool SteepestDirection(const RequestBounds& b, std::span<const double> plan, size_t free) {
    for (size_t k = 0; k < free; ++k) direction_[k] = -gradient_[k];
    ProjectOntoCone(b, plan, direction_.data(), free);
    double largest = 0.0;
    for (size_t k = 0; k < free; ++k) largest = std::max(largest, std::abs(direction_[k]));
    if (!(largest > 0.0)) return false;
    for (size_t k = 0; k < free; ++k) direction_[k] /= largest;
    return true;
  }

  // direction_ = the steepest descent in the plan's increments R(i) - R(i-1), those at the
  // speed limit that it would push beyond it held (moving R(i..) together: a move the cone's
  // projection may miss where its runs pool more than they must), as a change of the requests
  // scaled so that they move by at most 1 deg. False if no increment may move.
  bool IncrementDirection(const RequestBounds& b, std::span<const double> plan, size_t free) {
    const double tie = b.max_step_deg * (1.0 - 1e-9);
    double suffix = 0.0;  // d HorizonError / d (R(i) - R(i-1)): the gradient's sum from i on
    for (size_t i = free; i-- > 0;) {
      suffix += gradient_[i];
      const double step = plan[i] - (i == 0 ? b.previous_deg : plan[i - 1]);
      const bool held = (step <= -tie && suffix > 0.0) || (step >= tie && suffix < 0.0);
      direction_[i] = held ? 0.0 : -suffix;
    }
    double sum = 0.0;
    double largest = 0.0;
    for (size_t i = 0; i < free; ++i) {
      sum += direction_[i];
      direction_[i] = sum;
      largest = std::max(largest, std::abs(sum));
    }
    if (!(largest > 0.0)) return false;
    for (size_t i = 0; i < free; ++i) direction_[i] /= largest;
    return true;
  }

  // The memory's pair k, oldest first.
  const double* Step(size_t k) const { return &steps_[((first_ + k) % kRows) * decisions_]; }
  const double* Change(size_t k) const { return &changes_[((first_ + k) % kRows) * decisions_]; }

  // direction_ = -H g over the first `free` requests (the two-loop recursion, H0 = (s.y / y.y)
  // I from the newest pair), projected onto the cone. False unless it descends.
  bool QuasiNewtonDirection(const RequestBounds& b, std::span<const double> plan, size_t free) {
    const auto dot = [free](const double* u, const double* v) {
      double sum = 0.0;
      for (size_t i = 0; i < free; ++i) sum += u[i] * v[i];
      return sum;
    };
    double* q = direction_.data();
    std::copy(gradient_.begin(), gradient_.begin() + static_cast<long>(free), q);
    for (size_t k = count_; k-- > 0;) {
      rho_[k] = 1.0 / dot(Change(k), Step(k));
      alpha_[k] = rho_[k] * dot(Step(k), q);
      const double* y = Change(k);
      for (size_t i = 0; i < free; ++i) q[i] -= alpha_[k] * y[i];
    }
    const double* s_new = Step(count_ - 1);
    const double* y_new = Change(count_ - 1);
    const double scale = dot(s_new, y_new) / dot(y_new, y_new);
    for (size_t i = 0; i < free; ++i) q[i] *= scale;
    for (size_t k = 0; k < count_; ++k) {
      const double beta = rho_[k] * dot(Change(k), q);
      const double* s = Step(k);
      for (size_t i = 0; i < free; ++i) q[i] += (alpha_[k] - beta) * s[i];
    }
    for (size_t i = 0; i < free; ++i) q[i] = -q[i];
    ProjectOntoCone(b, plan, q, free);
    return dot(q, gradient_.data()) < 0.0;
  }

  size_t decisions_ = 0;
  std::vector<double> candidate_, gradient_, next_gradient_, direction_, held_, full_gradient_;
  // ProjectOntoCone's runs of requests that move together.
  struct Run {
    size_t first = 0;
    size_t size = 0;
    double sum = 0.0;     // of the move asked of its requests
    bool at_max = false;  // a request of it is at max_deg
    bool at_min = false;
    bool held = false;  // by R(t-1)
    // Its move: the mean asked, or 0 if R(t-1) holds it or it would push a request beyond a
    // limit.
    double Value() const {
      const double mean = sum / static_cast<double>(size);
      return held || (at_max && mean > 0.0) || (at_min && mean < 0.0) ? 0.0 : mean;
    }
  };
  std::vector<Run> runs_;
  std::vector<double> angles_, candidate_angles_;  // M(t..t+P) under the plan, the candidate
  // The memory: kRows rows of decisions_ values, a ring of count_ pairs from row first_, and
  // one row spare for a new pair that may not be kept.
  static constexpr size_t kRows = kMemory + 1;
  std::vector<double> steps_, changes_;
  size_t first_ = 0;
  size_t count_ = 0;
  std::array<double, kMemory> rho_{};
  std::array<double, kMemory> alpha_{};
  State scratch_;
};

}  // namespace leglab::servo_plan
