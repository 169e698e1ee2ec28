// The servo model ladder declared once (servo/ladder.json) and a rung added to it: fitted,
// scored, written and read as the ladder's own are.
#include "leglab/servo/ladder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "leglab/app/input_error.h"
#include "leglab/app/output.h"
#include "leglab/servo/log_fit.h"
#include "leglab/servo/servo_plan_io.h"
#include "log_fit_report.h"

namespace {

using Json = nlohmann::ordered_json;  // keeps the rungs' order
using leglab::ModelRung;
using leglab::RungKind;
using leglab::RungParameters;
using leglab::ServoRecording;
using leglab::ServoRung;

// servo/ladder.json read here with its own parser, beside the compiled-in copy.
Json LadderFile() {
  std::ifstream in(std::string(LEGLAB_SOURCE_DIR) + "/servo/ladder.json");
  return Json::parse(in);
}

TEST(ServoLadder, TheCompiledLadderIsTheFileAndEveryScoredRungIsImplemented) {
  const Json file = LadderFile();
  const auto ladder = leglab::ServoLadder();
  ASSERT_EQ(ladder.size(), file["rungs"].size());
  for (size_t k = 0; k < ladder.size(); ++k) {
    const Json& r = file["rungs"][k];
    EXPECT_EQ(ladder[k].name, r["name"]);
    EXPECT_EQ(ladder[k].label, r["label"]);
    EXPECT_EQ(ladder[k].description, r["description"]);
    EXPECT_EQ(ladder[k].column, r["column"]);
    const std::string kind = r["kind"];
    EXPECT_EQ(ladder[k].kind, kind == "baseline" ? RungKind::kBaseline
                              : kind == "model"  ? RungKind::kModel
                                                 : RungKind::kLearned)
        << kind;
  }
  // The paper's rungs and the oracle first, as every table shows them, the learned ones last.
  const std::vector<std::string> scored = {"direct", "best_shift", "paper", "extended"};
  const std::vector<ServoRung> rungs = leglab::LogFitRungs();
  ASSERT_EQ(rungs.size(), scored.size() + leglab::LadderModelRungs().size());
  for (size_t k = 0; k < scored.size(); ++k) EXPECT_EQ(rungs[k].name, scored[k]);
  const auto columns = leglab::LogCurveColumns();
  ASSERT_EQ(columns.size(), leglab::kLogColumnCount + rungs.size());
  for (size_t k = 0; k < rungs.size(); ++k) {
    EXPECT_EQ(columns[leglab::kLogColumnCount + k].name, rungs[k].name + "_deg");
    EXPECT_EQ(columns[leglab::kLogColumnCount + k].description, rungs[k].column);
  }
}

constexpr double kTrueGain = 0.3;  // the synthetic servo's: a first-order lag a tick

// A servo that closes kTrueGain of its error to the request of the tick before, every 10 ms:
// m(t) = m(t-1) + g (R(t-1) - m(t-1)), for a request of `shape`.
leglab::GivenServoLog FirstOrderLog(const std::string& trajectory, double frequency_hz) {
  leglab::ServoLog log{.file = trajectory + ".csv",
                       .motor = "m",
                       .trajectory = trajectory,
                       .kp = 32.0,
                       .mass_kg = 0.0,
                       .length_m = 0.0,
                       .samples = {}};
  double measured = 0.0, request = 0.0;
  for (int k = 0; k < 600; ++k) {
    measured += kTrueGain * (request - measured);
    request = 40.0 * std::sin(2.0 * M_PI * frequency_hz * 0.01 * k) + 10.0 * (k / 150 % 2);
    log.samples.push_back({.time_s = 0.01 * k,
                           .request_deg = request,
                           .measured_deg = k == 0 ? 0.0 : measured,
                           .torque_enabled = true});
  }
  log.samples[0].measured_deg = 0.0;
  return {std::move(log), true};
}

// The added rung: the same first-order lag, its gain fitted by least squares on the steps
// from one measured angle to the next.
ModelRung FirstOrderRung(int* fits) {
  ModelRung m;
  m.rung = {.name = "first_order",
            .kind = RungKind::kModel,
            .label = "first order",
            .description = "a first-order lag",
            .column = "the first-order lag's prediction"};
  m.fit = [fits](std::span<const ServoRecording> train, double) {
    double num = 0.0, den = 0.0;
    for (const ServoRecording& r : train) {
      for (size_t t = 1; t < r.scored.size(); ++t) {
        if (r.scored[t] == 0 || r.scored[t - 1] == 0) continue;
        const double error = r.request_deg[t - 1] - r.measured_deg[t - 1];
        num += (r.measured_deg[t] - r.measured_deg[t - 1]) * error;
        den += error * error;
      }
    }
    ++*fits;
    return RungParameters{{"gain", num / den}};
  };
  m.predict = [](const RungParameters& p, const ServoRecording& r, double) {
    std::vector<double> angle(r.request_deg.size());
    for (size_t t = 0; t < angle.size(); ++t) {
      angle[t] = t == 0 || r.scored[t] == 0 || r.scored[t - 1] == 0
                     ? r.measured_deg[t]
                     : angle[t - 1] + p.at("gain") * (r.request_deg[t - 1] - angle[t - 1]);
    }
    return angle;
  };
  return m;
}

TEST(ServoLadder, ARungAddedIsFittedScoredWrittenAndRead) {
  const leglab::LogFitConfig config = leglab::LogFitConfigFromOverrides(
      {"logs.cross_validate=leave_one_trajectory_out", "logs.iterations=20", "logs.tick_s=0.01"});
  int fits = 0;
  const std::vector<ModelRung> extra = {FirstOrderRung(&fits)};
  const leglab::LogFitResult result = leglab::FitServoLogs(
      config, 2, {FirstOrderLog("slow", 0.5), FirstOrderLog("fast", 1.5)}, extra);
  EXPECT_EQ(fits, 3);  // the final model and the two folds'
  const Json json = Json::parse(result.json);
  // Fitted: the final model's gain and each fold's are the servo's own.
  EXPECT_NEAR(json["models"]["first_order"]["m"]["gain"].get<double>(), kTrueGain, 1e-9);
  EXPECT_EQ(json["models"]["first_order"]["m"]["tick_s"].get<double>(), 0.01);
  ASSERT_EQ(json["folds"].size(), 2u);
  for (const Json& fold : json["folds"]) {
    EXPECT_NEAR(fold["first_order"]["gain"].get<double>(), kTrueGain, 1e-9) << fold;
  }
  // Scored: on every row, after the ladder's own, and predicting the servo exactly.
  ASSERT_EQ(json["logs"].size(), 4u);  // each log in sample and held out
  for (const Json& row : json["logs"]) {
    std::vector<std::string> keys;
    for (const auto& [key, value] : row["mae_deg"].items()) keys.push_back(key);
    EXPECT_EQ(keys.back(), "first_order") << row;
    EXPECT_LT(row["mae_deg"]["first_order"].get<double>(), 1e-9) << row;
    EXPECT_GT(row["mae_deg"]["direct"].get<double>(), 1.0) << row;
  }
  // Written: log_fit.md's heading and key, each log's CSV column.
  EXPECT_NE(result.markdown.find("| extended | first order |"), std::string::npos);
  EXPECT_NE(result.markdown.find("first order: a first-order lag. "), std::string::npos);
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "leglab_ladder_test";
  std::filesystem::remove_all(dir);
  {
    leglab::OutputDir out(dir, {"log_"});
    for (const leglab::LogFitCurves& c : result.curves) leglab::log_fit::WriteLogCsv(c, out);
    out.Commit();
  }
  for (const leglab::LogFitCurves& c : result.curves) {
    ASSERT_EQ(c.rungs.back(), "first_order");
    double sum = 0.0;
    for (size_t t = 0; t < c.measured_deg.size(); ++t) {
      sum += std::abs(c.predicted_deg.back()[t] - c.measured_deg[t]);
    }
    EXPECT_LT(sum / static_cast<double>(c.measured_deg.size()), 1e-9) << c.name;
  }
  std::ifstream csv(dir / "log_m_slow.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header,
            "time_s,request_deg,measured_deg,torque_enabled,direct_deg,best_shift_deg,paper_deg,"
            "extended_deg,first_order_deg");
  // Read: the plan's reader takes the ladder's own models from the same file, unmoved.
  EXPECT_NO_THROW(leglab::ParseFittedModel(result.json, "extended", "m", "test"));
}

TEST(ServoLadder, AnAddedRungNamedBadlyIsRefusedNamingIt) {
  const leglab::LogFitConfig config =
      leglab::LogFitConfigFromOverrides({"logs.cross_validate=none", "logs.tick_s=0.01"});
  int fits = 0;
  for (const std::string name : {"First", "two words", "", "paper", "best_shift"}) {
    ModelRung m = FirstOrderRung(&fits);
    m.rung.name = name;
    try {
      leglab::FitServoLogs(config, 1, {FirstOrderLog("slow", 0.5)}, std::vector<ModelRung>{m});
      ADD_FAILURE() << name;
    } catch (const leglab::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("rung '" + name + "'"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(fits, 0);
}

}  // namespace
