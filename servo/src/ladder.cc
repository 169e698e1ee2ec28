#include "leglab/servo/ladder.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string_view>

#include "ladder_json.h"

namespace leglab {
namespace {

using Json = nlohmann::json;

// The rungs log_fit.cc implements itself: the baselines and the two models it plans with.
constexpr std::array<std::string_view, 4> kBuiltInRungs{"direct", "best_shift", "paper",
                                                        "extended"};

constexpr std::array<std::string_view, 3> kRungKindNames{"baseline", "model", "learned"};

std::string Text(const Json& rung, const char* field, size_t index) {
  if (!rung.contains(field) || !rung[field].is_string() || rung[field].get<std::string>().empty()) {
    throw std::logic_error("servo/ladder.json: rungs[" + std::to_string(index) + "]." + field +
                           ": expected a non-empty string");
  }
  return rung[field].get<std::string>();
}

std::vector<ServoRung> ParseLadder() {
  const Json json = Json::parse(kLadderJson, nullptr, /*allow_exceptions=*/false);
  if (!json.is_object() || !json.contains("rungs") || !json["rungs"].is_array()) {
    throw std::logic_error("servo/ladder.json: expected an object with a rungs array");
  }
  std::vector<ServoRung> ladder;
  for (size_t i = 0; i < json["rungs"].size(); ++i) {
    const Json& r = json["rungs"][i];
    ServoRung rung{.name = Text(r, "name", i),
                   .kind = RungKind::kModel,
                   .label = Text(r, "label", i),
                   .description = Text(r, "description", i),
                   .column = Text(r, "column", i)};
    const std::string kind = Text(r, "kind", i);
    const auto* found = std::find(kRungKindNames.begin(), kRungKindNames.end(), kind);
    if (found == kRungKindNames.end()) {
      throw std::logic_error("servo/ladder.json: rungs[" + std::to_string(i) + "].kind: '" + kind +
                             "' is not baseline, model or learned");
    }
    rung.kind = static_cast<RungKind>(found - kRungKindNames.begin());
    for (const ServoRung& before : ladder) {
      if (before.name == rung.name) {
        throw std::logic_error("servo/ladder.json: the rung '" + rung.name + "' is declared twice");
      }
    }
    ladder.push_back(std::move(rung));
  }
  return ladder;
}

// The implementations of the ladder's further model rungs, one a rung (see docs/extending.md,
// "A new model rung"): none yet beyond the built-in ones.
std::vector<ModelRung> ImplementedModelRungs() { return {}; }

std::vector<ModelRung> CheckedModelRungs() {
  std::vector<ModelRung> implemented = ImplementedModelRungs();
  std::vector<ModelRung> rungs;
  for (const ServoRung& rung : ServoLadder()) {
    if (rung.kind == RungKind::kLearned ||
        std::find(kBuiltInRungs.begin(), kBuiltInRungs.end(), rung.name) != kBuiltInRungs.end()) {
      continue;
    }
    const auto it = std::find_if(implemented.begin(), implemented.end(),
                                 [&](const ModelRung& m) { return m.rung.name == rung.name; });
    if (it == implemented.end() || rung.kind != RungKind::kModel) {
      throw std::logic_error("servo/ladder.json: identify has no implementation of the rung '" +
                             rung.name + "' (docs/extending.md, \"A new model rung\")");
    }
    it->rung = rung;
    rungs.push_back(*it);
  }
  return rungs;
}

}  // namespace

std::span<const ServoRung> ServoLadder() {
  static const std::vector<ServoRung> ladder = ParseLadder();
  return ladder;
}

std::span<const ModelRung> LadderModelRungs() {
  static const std::vector<ModelRung> rungs = CheckedModelRungs();
  return rungs;
}

}  // namespace leglab
