// docs/extending.md's recipe for a new controller mode, proven: BlendController (extending/) is
// one file pair and one registry line, and these libraries were built with it. Everything
// else must follow: its keys in the loader and the key reference, its run in track's
// pipeline, its output files and its row of Table 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "blend_controller.h"
#include "leglab/app/output.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/tables.h"
#include "leglab/experiments/track.h"
#include "leglab/experiments/writers.h"

namespace leglab::experiments {
namespace {

namespace fs = std::filesystem;

const std::string kTrack = std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/track.yaml";

// A short walk on the ideal plant with a given model: deterministic and fast.
std::vector<std::string> Quick(std::vector<std::string> more) {
  std::vector<std::string> o = {
      "plant=model", "warmup_steps=12", "steps=2", "track.search_shift=false",
      "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"};
  o.insert(o.end(), more.begin(), more.end());
  return o;
}

std::string ErrorOf(const std::vector<std::string>& overrides) {
  try {
    LoadExperimentConfig(kTrack, overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Extending, TheRegistryListsTheNewModeAfterTheShippedOnes) {
  const auto modes = ControllerModes();
  ASSERT_EQ(modes.size(), 7u);
  EXPECT_EQ(modes.back().name, "blend");
  EXPECT_EQ(modes.back().label, "Bl");
  EXPECT_EQ(modes.back().config_section, "blend");
  EXPECT_TRUE(modes.back().feed_forward);
}

TEST(Extending, ItsKeysAreInTheReferenceWithTheirRanges) {
  const KeyRow* gain = FindKey("blend.gain");
  ASSERT_NE(gain, nullptr);
  EXPECT_EQ(gain->type, "number");
  EXPECT_EQ(gain->default_text, "0.5");
  EXPECT_EQ(gain->range, "[0, 1]");
  const KeyRow* lead = FindKey("blend.lead_ticks");
  ASSERT_NE(lead, nullptr);
  EXPECT_EQ(lead->unit, "ticks");
  const std::string table = KeyTableMarkdown(ExperimentKeys({}));
  EXPECT_NE(table.find("| `blend.gain` | number | 0.5 | [0, 1] |  | "), std::string::npos);
}

TEST(Extending, TheLoaderReadsAndChecksItsKeys) {
  const ExperimentConfig config =
      LoadExperimentConfig(kTrack, Quick({"controller.modes=[blend]", "blend.gain=0.25"}));
  ASSERT_EQ(config.controllers.size(), 1u);
  const auto& spec = std::get<BlendController::Spec>(config.controllers[0]);
  EXPECT_EQ(spec.gain, 0.25);
  EXPECT_EQ(spec.lead_ticks, 4);
  EXPECT_NE(ErrorOf(Quick({"blend.gain=2"})).find("config: blend.gain must be in [0, 1], got 2"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Quick({"blend.gian=0.1"})).find("unknown key 'blend.gian'"), std::string::npos);
  EXPECT_NE(ErrorOf(Quick({"controller.modes=[blend, blend]"})).find("twice"), std::string::npos);
}

// gain 0 requests D(t) exactly, so the plant does what it does under the direct method, tick
// for tick; gain 1 requests D(t + k) up to rounding, the time shift by k.
TEST(Extending, ItRunsThroughTracksPipeline) {
  const TrackResult zero = RunTrackExperiment(
      LoadExperimentConfig(kTrack, Quick({"controller.modes=[direct, blend]", "blend.gain=0"})));
  ASSERT_EQ(zero.runs.size(), 2u);
  EXPECT_EQ(zero.runs[1].run.measured_deg, zero.runs[0].run.measured_deg);
  EXPECT_EQ(zero.runs[1].foot_error_cm, zero.runs[0].foot_error_cm);

  const TrackResult one = RunTrackExperiment(LoadExperimentConfig(
      kTrack, Quick({"controller.modes=[time_shift, blend]", "controller.shift_ticks=6",
                     "blend.gain=1", "blend.lead_ticks=6"})));
  ASSERT_EQ(one.runs.size(), 2u);
  const auto& shifted = one.runs[0].run.measured_deg;
  const auto& blended = one.runs[1].run.measured_deg;
  ASSERT_EQ(shifted.size(), blended.size());
  for (size_t i = 0; i < shifted.size(); ++i) {
    for (int j = 0; j < kLegJoints; ++j) ASSERT_NEAR(blended[i][j], shifted[i][j], 1e-9) << i;
  }
}

TEST(Extending, ItsOutputFilesAndTableRowFollow) {
  const fs::path dir = fs::temp_directory_path() / "leglab_extending_test";
  fs::remove_all(dir);
  const ExperimentConfig config =
      LoadExperimentConfig(kTrack, Quick({"controller.modes=[direct, blend]"}));
  const TrackResult result = RunTrackExperiment(config);
  {
    OutputDir out(dir, TrackOutputPrefixes());
    const Table2 table = ComputeTable2(result);
    for (const ModeRun& run : result.runs) WriteModeOutputs(run, result, out);
    WriteTrackTables(result, table, config, out);
    out.Commit();
  }
  EXPECT_TRUE(fs::exists(dir / "trace_blend.csv"));
  EXPECT_TRUE(fs::exists(dir / "foot_blend.csv"));
  std::ifstream md(dir / "table2.md");
  std::stringstream text;
  text << md.rdbuf();
  EXPECT_NE(text.str().find("Bl"), std::string::npos) << text.str();
  std::ifstream json(dir / "table2.json");
  std::stringstream json_text;
  json_text << json.rdbuf();
  EXPECT_NE(json_text.str().find("\"blend\""), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace leglab::experiments
