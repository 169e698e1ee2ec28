#pragma once

// The `plan` program (servo/plan.cc): its flags, and the run that reads a fitted model and a
// desired motion (servo_plan_io.h), plans and writes requests.csv and plan.json.
#include <array>
#include <optional>
#include <span>
#include <string>

#include "leglab/app/output_docs.h"
#include "leglab/servo/servo_plan_io.h"

namespace leglab {

/// What `plan` is asked (its flags; see docs/real-servos.md, "Requests for a real servo").
struct PlanOptions {
  std::string model_path;              ///< --model: identify's log_fit.json
  std::string rung = "extended";       ///< --rung: paper or extended
  std::string method = "model_based";  ///< --method: model_based or optimal
  std::string desired_path;            ///< --desired: a desired CSV or a servo log
  std::string out_dir;                 ///< --out
  std::string motor;                   ///< --motor (empty: from the log or the only one)
  std::optional<double> kp;            ///< --kp
  std::optional<double> mass_kg;       ///< --mass-kg
  std::optional<double> length_m;      ///< --length-m
  double min_deg = -180.0;             ///< --min-deg
  double max_deg = 180.0;              ///< --max-deg
  /// --online: the requests of a ServoPlanner run tick by tick on the model itself, given
  /// `preview_ticks` desired angles ahead (unset: the method's own), instead of the batch plan.
  bool online = false;
  std::optional<int> preview_ticks;  ///< --preview-ticks (with --online)
  /// --budget-ms (with --online --method optimal): ServoPlannerOptions::budget_s in ms.
  std::optional<double> budget_ms;
  std::optional<int> hold_ticks;           ///< --hold-ticks (with --online --method optimal)
  std::optional<int> handover_ticks;       ///< --handover-ticks (likewise)
  std::optional<int> iterations_per_tick;  ///< --iterations-per-tick (likewise)
  bool progress = false;  ///< --progress: plain progress lines on stderr (with --online)
  bool quiet = false;     ///< --quiet: no progress
};

/// Runs `plan`: reads the model and the desired motion, plans, writes requests.csv and plan.json
/// into `options.out_dir` (all or nothing) and returns the one-paragraph summary. Throws
/// InputError on bad input, having written nothing.
std::string RunPlan(const PlanOptions& options);

/// `plan`'s main: parses the flags and runs RunPlan, reporting errors as ReportErrors does.
int PlanMain(int argc, char** argv);

/// The columns of plan's requests.csv (and of leglab.servo.plan's dict), one row per tick of
/// the model's tick.
inline constexpr std::array<ColumnDoc, 5> kRequestsColumns{{
    {"time_s", "s", "the tick's time from the motion's start"},
    {"desired_deg", "deg", "the desired angle, resampled onto the model's tick"},
    {"request_deg", "deg", "the planned request"},
    {"predicted_deg", "deg", "the model's angle under the planned requests"},
    {"beyond_servo", "",
     "1 where the model-based inversion cannot reach the desired angle (a property of the "
     "motion)"},
}};

/// What plan writes: its `--list-outputs`.
std::span<const OutputDoc> PlanOutputs();

}  // namespace leglab
