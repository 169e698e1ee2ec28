#pragma once

#include <concepts>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
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
///   static constexpr ControllerModeTraits kTraits{...};  its optional traits, in one block
///   static void VisitKeys(KeyVisitor&, Spec&);    its config keys, declared once
///   Mode(const Spec&, const ControllerContext&);  its factory
/// and the static functions its kTraits' `has_` flags declare (ControllerModeTraits). The
/// registry checks all of it at compile time (CheckControllerMode), each failure a message
/// naming the member.
template <typename Mode>
constexpr void CheckControllerModeFunctions();

/// Checks a controller mode class at compile time (the registry does, for every registered
/// mode): each failure is a static_assert whose message names the member that is missing,
/// declared loose instead of in kTraits, or flagged in kTraits but absent (a misspelt function).
template <typename Mode>
constexpr void CheckControllerMode() {
  static_assert(std::is_base_of_v<JointController, Mode>,
                "a controller mode must derive from JointController");
  static_assert(
      requires { typename Mode::Spec; }, "a controller mode needs struct Spec");
  static_assert(
      requires { std::string_view(Mode::kName); },
      "a controller mode needs static constexpr std::string_view kName");
  static_assert(
      requires { std::string_view(Mode::kLabel); },
      "a controller mode needs static constexpr std::string_view kLabel");
  static_assert(
      requires(KeyVisitor & v, typename Mode::Spec & s) { Mode::VisitKeys(v, s); },
      "a controller mode needs static void VisitKeys(KeyVisitor&, Spec&)");
  static_assert(
      std::is_constructible_v<Mode, const typename Mode::Spec&, const ControllerContext&>,
      "a controller mode needs a constructor Mode(const Spec&, const ControllerContext&)");
  static_assert(
      requires {
        requires std::same_as<std::remove_cvref_t<decltype(Mode::kTraits)>, ControllerModeTraits>;
      },
      "a controller mode needs static constexpr ControllerModeTraits kTraits{...}");
  // The traits of before the block, declared loose, would be ignored: refused with the field
  // that replaces each.
  static_assert(
      !requires { Mode::kFeedForward; }, "kFeedForward is kTraits.feed_forward");
  static_assert(
      !requires { Mode::kFollowsApproximation; },
      "kFollowsApproximation is kTraits.follows_approximation");
  static_assert(
      !requires { Mode::kEstimatesModel; }, "kEstimatesModel is kTraits.estimates_model");
  static_assert(
      !requires { Mode::kConfigSection; }, "kConfigSection is kTraits.config_section");
  static_assert(
      !requires { Mode::kSearchFile; }, "kSearchFile is kTraits.search_file");
  if constexpr (requires { Mode::kTraits; }) CheckControllerModeFunctions<Mode>();
}

/// CheckControllerMode's half for the static functions kTraits' `has_` flags declare.
template <typename Mode>
constexpr void CheckControllerModeFunctions() {
  constexpr ControllerModeTraits traits = Mode::kTraits;
  using Spec = typename Mode::Spec;
  static_assert(
      traits.has_search_candidates ==
          requires(const Spec& s, const ControllerContext& c) {
            { Mode::SearchCandidates(s, c) } -> std::same_as<std::vector<Spec>>;
          },
      "kTraits.has_search_candidates must say whether the mode has static "
      "std::vector<Spec> SearchCandidates(const Spec&, const ControllerContext&)");
  static_assert(traits.has_search_candidates == !traits.search_file.empty(),
                "kTraits.search_file names where a search's scores go: set exactly when "
                "has_search_candidates");
  static_assert(
      traits.has_request_lead ==
          requires(const Spec& s) {
            { Mode::RequestLeadTicks(s) } -> std::same_as<int>;
          },
      "kTraits.has_request_lead must say whether the mode has static int "
      "RequestLeadTicks(const Spec&)");
  static_assert(!traits.has_request_lead || traits.has_search_candidates,
                "kTraits.has_request_lead needs has_search_candidates");
  static_assert(
      traits.has_walk_models ==
          requires(const Spec& s) {
            { Mode::ModelFittedToWalk(s) } -> std::same_as<bool>;
          },
      "kTraits.has_walk_models must say whether the mode has static bool "
      "ModelFittedToWalk(const Spec&)");
  static_assert(
      traits.has_parameters ==
          requires(const Spec& s) {
            { Mode::Parameters(s) } -> std::same_as<std::vector<std::pair<std::string_view, long>>>;
          },
      "kTraits.has_parameters must say whether the mode has static "
      "std::vector<std::pair<std::string_view, long>> Parameters(const Spec&)");
}

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
