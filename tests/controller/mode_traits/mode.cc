// A controller mode written several ways, compiled one way at a time (-DCASE=n) by
// mode_traits_test.cmake: case 0 is a well-formed mode and compiles; every other case is one
// mistake, which the compiler or CheckControllerMode must refuse with a message naming it.
#include "leglab/controller/registry.h"

namespace {

struct Mode : leglab::JointController {
  struct Spec {
    friend bool operator==(const Spec&, const Spec&) = default;
  };
  static constexpr std::string_view kName = "probe";
  static constexpr std::string_view kLabel = "Pr";
#if CASE == 1  // a misspelt field
  static constexpr leglab::ControllerModeTraits kTraits{.feed_forwrd = true};
#elif CASE == 2  // a trait of before the block, declared loose
  static constexpr leglab::ControllerModeTraits kTraits{};
  static constexpr bool kFeedForward = true;
#elif CASE == 3  // a flagged function, misspelt
  static constexpr leglab::ControllerModeTraits kTraits{.has_walk_models = true};
  static bool ModelFitedToWalk(const Spec&) { return true; }
#elif CASE == 4  // a function without its flag
  static constexpr leglab::ControllerModeTraits kTraits{};
  static std::vector<std::pair<std::string_view, long> > Parameters(const Spec&) { return {}; }
#elif CASE == 5  // no traits block
#else
  static constexpr leglab::ControllerModeTraits kTraits{.has_walk_models = true};
  static bool ModelFittedToWalk(const Spec&) { return true; }
#endif
  static void VisitKeys(leglab::KeyVisitor&, Spec&) {}
  Mode(const Spec&, const leglab::ControllerContext&) {}
  leglab::LegAngles Update(long, const leglab::LegAngles& measured) override { return measured; }
  std::string_view name() const override { return kName; }
};

static_assert((leglab::CheckControllerMode<Mode>(), true));

}  // namespace
