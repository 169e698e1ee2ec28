#include "leglab/controller/registry.h"

#include <array>
#include <stdexcept>

namespace leglab {
namespace {

template <typename Mode>
constexpr ControllerModeInfo InfoOf() {
  CheckControllerMode<Mode>();
  constexpr ControllerModeTraits traits = Mode::kTraits;
  return {.name = Mode::kName,
          .label = Mode::kLabel,
          .feed_forward = traits.feed_forward,
          .follows_approximation = traits.follows_approximation,
          .searchable = traits.has_search_candidates,
          .searchable_by_lead = traits.has_request_lead,
          .search_file = traits.search_file,
          .config_section = traits.config_section,
          .estimates_model = traits.estimates_model};
}

template <typename List>
struct Registry;

template <typename... Modes>
struct Registry<ControllerModeList<Modes...>> {
  static constexpr std::array<ControllerModeInfo, sizeof...(Modes)> kInfo = {InfoOf<Modes>()...};

  // Calls fn.template operator()<Mode>() for the mode at `index` (registry order) and returns
  // its result.
  template <typename Result, typename Fn>
  static Result Dispatch(size_t index, Fn&& fn) {
    Result result{};
    size_t i = 0;
    ((i++ == index ? (void)(result = fn.template operator()<Modes>()) : void()), ...);
    return result;
  }
};

using Modes = Registry<RegisteredControllerModes>;

size_t IndexOf(std::string_view name) {
  for (size_t i = 0; i < Modes::kInfo.size(); ++i) {
    if (Modes::kInfo[i].name == name) return i;
  }
  throw std::invalid_argument("unknown controller mode '" + std::string(name) +
                              "' (valid: " + ControllerModeNames() + ")");
}

}  // namespace

std::span<const ControllerModeInfo> ControllerModes() { return Modes::kInfo; }

std::string ControllerModeNames() {
  std::string names;
  for (const ControllerModeInfo& m : Modes::kInfo) {
    if (!names.empty()) names += ", ";
    names += m.name;
  }
  return names;
}

const ControllerModeInfo& FindControllerMode(std::string_view name) {
  return Modes::kInfo[IndexOf(name)];
}

const ControllerModeInfo& ModeOf(const ControllerSpec& spec) { return Modes::kInfo[spec.index()]; }

ControllerSpec ReadControllerSpec(std::string_view name, KeyVisitor& visitor) {
  return Modes::Dispatch<ControllerSpec>(IndexOf(name), [&]<typename Mode>() {
    typename Mode::Spec spec{};
    Mode::VisitKeys(visitor, spec);
    return ControllerSpec(std::in_place_type<typename Mode::Spec>, spec);
  });
}

std::unique_ptr<JointController> MakeController(const ControllerSpec& spec,
                                                const ControllerContext& context) {
  return Modes::Dispatch<std::unique_ptr<JointController>>(
      spec.index(), [&]<typename Mode>() -> std::unique_ptr<JointController> {
        return std::make_unique<Mode>(std::get<typename Mode::Spec>(spec), context);
      });
}

std::vector<ControllerSpec> SearchCandidates(const ControllerSpec& spec,
                                             const ControllerContext& context) {
  return Modes::Dispatch<std::vector<ControllerSpec>>(spec.index(), [&]<typename Mode>() {
    std::vector<ControllerSpec> out;
    const auto& own = std::get<typename Mode::Spec>(spec);
    if constexpr (Mode::kTraits.has_search_candidates) {
      for (auto& candidate : Mode::SearchCandidates(own, context)) {
        out.emplace_back(std::in_place_type<typename Mode::Spec>, std::move(candidate));
      }
    } else {
      out.push_back(spec);
    }
    return out;
  });
}

std::optional<int> RequestLeadTicks(const ControllerSpec& spec) {
  return Modes::Dispatch<std::optional<int>>(spec.index(), [&]<typename Mode>() {
    std::optional<int> lead;
    if constexpr (Mode::kTraits.has_request_lead) {
      lead = Mode::RequestLeadTicks(std::get<typename Mode::Spec>(spec));
    }
    return lead;
  });
}

bool UsesWalkModels(const ControllerSpec& spec) {
  return Modes::Dispatch<bool>(spec.index(), [&]<typename Mode>() {
    if constexpr (Mode::kTraits.has_walk_models) {
      return Mode::ModelFittedToWalk(std::get<typename Mode::Spec>(spec));
    } else {
      return false;
    }
  });
}

std::vector<std::pair<std::string_view, long>> ModeParameters(const ControllerSpec& spec) {
  return Modes::Dispatch<std::vector<std::pair<std::string_view, long>>>(
      spec.index(), [&]<typename Mode>() {
        std::vector<std::pair<std::string_view, long>> out;
        if constexpr (Mode::kTraits.has_parameters) {
          out = Mode::Parameters(std::get<typename Mode::Spec>(spec));
        }
        return out;
      });
}

}  // namespace leglab
