#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "leglab/controller/adaptive_controller.h"
#include "leglab/controller/controller.h"
#include "leglab/controller/direct_controller.h"
#include "leglab/controller/ilc_controller.h"
#include "leglab/controller/model_based_controller.h"
#include "leglab/controller/optimal_controller.h"
#include "leglab/controller/time_shift_controller.h"

#ifdef LEGLAB_EXTRA_MODES_HEADER
// A build of the libraries with modes of its own after the registered ones (the test that
// proves docs/extending.md): the header declares them and defines LEGLAB_EXTRA_MODES as
// ", ModeA, ModeB".
#include LEGLAB_EXTRA_MODES_HEADER
#else
#define LEGLAB_EXTRA_MODES
#endif

namespace leglab {

/// A list of controller mode classes. Each is a JointController with
///   struct Spec;                                  its options (a value type with ==)
///   static constexpr std::string_view kName;      its name in configs and file names
///   static constexpr std::string_view kLabel;     its short label in Table 2's keys
///   static void VisitKeys(KeyVisitor&, Spec&);    its config keys, declared once
///   Mode(const Spec&, const ControllerContext&);  its factory
/// and optionally
///   static constexpr bool kFeedForward = true;    requests periodic, independent of measurements
///   static constexpr bool kFollowsApproximation = true;  Table 2 also compares it with P
///   static constexpr bool kEstimatesModel = true;  ModelEstimates() reports its joint models
///   static std::vector<Spec> SearchCandidates(const Spec&, const ControllerContext&);
///   static constexpr std::string_view kSearchFile;  where a search's scores go (no .csv)
///   static constexpr std::string_view kConfigSection;  the config map of its keys (default
///                                                      "controller")
///   static std::vector<std::pair<std::string_view, long>> Parameters(const Spec&);
///   static bool ModelFittedToWalk(const Spec&);  the experiments build it with models fitted to
///                                                the walk, not the step tests' (see
///                                                UsesWalkModels)
///   static int RequestLeadTicks(const Spec&);    a search candidate requests what the
///                                                candidate with lead 0 requests, this many
///                                                ticks earlier: R(t) = R_0(t + lead)
template <typename... Modes>
struct ControllerModeList {
  using Spec = std::variant<typename Modes::Spec...>;
};

/// THE registry: every controller mode, in the order tables list them. A new mode is its own
/// file pair, its class here and its source in controller/CMakeLists.txt (docs/extending.md).
using RegisteredControllerModes =
    ControllerModeList<DirectController, TimeShiftController, ModelBasedController,
                       OptimalController, IlcController, AdaptiveController LEGLAB_EXTRA_MODES>;

/// One mode's options: the variant alternative of its class's Spec.
using ControllerSpec = RegisteredControllerModes::Spec;

/// What the experiments need to know about a mode besides building it.
struct ControllerModeInfo {
  std::string_view name;       ///< in configs (controller.mode/modes) and output file names
  std::string_view label;      ///< in Table 2's keys, e.g. "MB" in L2(Des,MB)
  bool feed_forward;           ///< requests periodic and independent of what is measured
  bool follows_approximation;  ///< Table 2 also compares it with the approximation P
  bool searchable;             ///< has SearchCandidates (searched when the experiment asks)
  /// Has RequestLeadTicks: on a time-invariant plant in steady state, a candidate's response is
  /// the lead-0 candidate's response `lead` ticks earlier, so one run scores every candidate.
  bool searchable_by_lead;
  std::string_view search_file;     ///< a searched mode's output file (without .csv)
  std::string_view config_section;  ///< the config map of its keys ("controller", "ilc")
  bool estimates_model = false;     ///< reports its joint models (ModelEstimates) every step
};

/// Every registered mode, in registry order.
std::span<const ControllerModeInfo> ControllerModes();

/// The registered names joined by ", " (for messages).
std::string ControllerModeNames();

/// The mode called `name`; throws std::invalid_argument "unknown controller mode 'x' (valid:
/// ...)".
const ControllerModeInfo& FindControllerMode(std::string_view name);

/// The mode of `spec`.
const ControllerModeInfo& ModeOf(const ControllerSpec& spec);

/// Mode `name`'s options: its Spec's defaults, visited by `visitor` (its VisitKeys: a loader
/// reads them, a lister lists them); throws as FindControllerMode for an unknown name, and
/// what the visitor throws.
ControllerSpec ReadControllerSpec(std::string_view name, KeyVisitor& visitor);

/// Builds the controller of `spec` for `context`; throws what the mode's constructor throws.
std::unique_ptr<JointController> MakeController(const ControllerSpec& spec,
                                                const ControllerContext& context);

/// The specs an experiment searches for the best one: the mode's SearchCandidates, or just
/// `spec` for a mode without.
std::vector<ControllerSpec> SearchCandidates(const ControllerSpec& spec,
                                             const ControllerContext& context);

/// The mode's RequestLeadTicks(spec) when it has one: spec's requests are those of the same
/// mode's lead-0 candidate `lead` ticks ahead. Empty for a mode without.
std::optional<int> RequestLeadTicks(const ControllerSpec& spec);

/// The mode's ModelFittedToWalk(spec) when it has one (false without): the experiments then give
/// `spec` a context whose models were fitted to the plant's response to the walk (the paper's
/// model-based requests) instead of the step tests' (or given) models.
bool UsesWalkModels(const ControllerSpec& spec);

/// Named integer parameters of `spec` worth reporting (e.g. time_shift's {"k", 8}); empty for a
/// mode without Parameters.
std::vector<std::pair<std::string_view, long>> ModeParameters(const ControllerSpec& spec);

}  // namespace leglab
