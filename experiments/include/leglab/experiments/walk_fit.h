#pragma once

#include <array>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/app/output_docs.h"
#include "leglab/experiments/config.h"

namespace leglab::experiments {

/// One continuous unknown of the walk behind the paper's Table 2: its config key, the range the
/// fit may use (in the key's unit) and why that range.
struct WalkUnknown {
  const char* key;
  double min;
  double max;
  const char* why;
};

/// The number of continuous unknowns (the ground depth, body pitch, locus skew and ground
/// fraction of desired.locus).
inline constexpr int kWalkUnknowns = 4;

/// The numbers the walk is fitted to: the paper's direct-method row of Table 2, joint L2 and
/// L-infinity (Des vs Dir, deg) and foot L2 and L-infinity (cm).
inline constexpr int kWalkFitTargets = 8;

/// One number the walk is fitted to: its name in walk_fit.json and the paper's value.
struct WalkFitTarget {
  std::string name;
  double paper;
};

/// A walk: which of the cited offsets is forward (an index into the two readings, 49 / 28 mm or
/// 28 / 49 mm forward / outward) and the continuous unknowns (WalkUnknown order).
struct FittedWalk {
  int offsets = 0;
  std::array<double, kWalkUnknowns> x{};
};

/// The direct method's row on one walk.
struct WalkEvaluation {
  bool feasible = false;
  std::string infeasible;                        ///< why not (the unreachable point)
  std::array<double, kWalkFitTargets> values{};  ///< in WalkFitTarget order
  /// Sum of squared relative residuals (each of the eight numbers counts alike); infinite when
  /// infeasible.
  double cost = std::numeric_limits<double>::infinity();
};

/// What fit_walk found: the walk, its row at the fit's cheap step counts and at the config's
/// own, and what the fit cost.
struct WalkFitReport {
  std::array<WalkFitTarget, kWalkFitTargets> targets;
  FittedWalk walk;
  WalkEvaluation at_fit_steps;    ///< the fitted walk at the fit's warm-up and steps
  WalkEvaluation check;           ///< the fitted walk at the config's warm-up and steps
  long evaluations = 0;           ///< walks run in all
  long feasible_evaluations = 0;  ///< of the grid's points, those the leg can reach
  int fit_warmup_steps = 0;
  int fit_steps = 0;
  int check_warmup_steps = 0;
  int check_steps = 0;
};

/// Whether fit_walk fits `key` (a desired.locus key, or its section): a --set of it would be
/// silently replaced by the fit.
bool IsFittedWalkKey(std::string_view key);

/// Recovers the walk behind the paper's Table 2 from its direct-method row alone. The paper
/// names only the walk's origin (the UT Austin Villa 2003 half-ellipse) and its step time; the
/// unknowns of the desired trajectory (where the locus sits below the shoulder, the body's
/// pitch, the locus skew, which cited offset is forward, the ground fraction) are fitted, each
/// inside a range justified from the cited walk and the ERS-210A's geometry, to the direct
/// method's eight numbers (kWalkFitTargets); the time-shift and model-based rows stay held out.
///
/// Deterministic: a fixed grid over the ranges, then a Nelder-Mead polish (fixed start simplex,
/// fixed iteration count) from the best grid point of each offset reading. Each evaluation runs
/// `config` (which must run the direct mode alone, with a fixed model) for one warm-up and two
/// measured steps (the direct method's error is periodic after one step), evaluations in
/// parallel on `threads` threads (the result does not depend on the count); the fitted walk is
/// then run with `config`'s own warmup_steps and steps for the reported residuals.
/// Throws InputError when no walk of the grid is reachable by the leg.
WalkFitReport FitWalk(const ExperimentConfig& config, int threads);

/// walk_fit.json: the config and overrides the fit ran with (`config_path`, `overrides`), the
/// numbers fitted on, the fitted walk, each unknown's range and why, the residuals and the cost.
std::string WalkFitJson(const WalkFitReport& report, const std::string& config_path,
                        const std::vector<std::string>& overrides);

/// walk_fit.md: the same as a page of Markdown tables (also what fit_walk prints).
std::string WalkFitMarkdown(const WalkFitReport& report);

/// What fit_walk writes: its `--list-outputs`.
std::span<const OutputDoc> WalkFitOutputs();

}  // namespace leglab::experiments
