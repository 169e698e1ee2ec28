// Controllers from outside the registry (ExternalMode, as the Python bindings pass them) in
// track's experiment: checked before anything runs, run as a registered mode is, their rows in
// the tables and files under their own names; and the trace and foot tables as values
// (ModeTraceRows into a ColumnTable), cell for cell what the CSV files hold.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

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
ExperimentConfig QuickModelPlant() {
  return LoadExperimentConfig(
      kTrack, {"plant=model", "warmup_steps=12", "steps=2", "controller.modes=[direct]",
               "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"});
}

// The simulated leg (noise, the seed) for a few steps, the models given so that nothing is
// identified.
ExperimentConfig QuickSimPlant() {
  return LoadExperimentConfig(
      kTrack, {"warmup_steps=1", "steps=2", "controller.modes=[direct]",
               "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"});
}

// The direct controller written again outside the registry: it requests the desired angles.
class MyDirect final : public JointController {
 public:
  explicit MyDirect(const ControllerContext& context) : desired_(context.desired) {}
  LegAngles Update(long tick, const LegAngles& /*measured_deg*/) override {
    return CycleAt(desired_, tick);
  }
  std::string_view name() const override { return "mine"; }

 private:
  DesiredCycle desired_;
};

ExternalMode Mine(std::string name = "mine") {
  return {std::move(name),
          [](const ControllerContext& context) { return std::make_unique<MyDirect>(context); }};
}

// The cells of a table as the trace and foot files hold them.
struct Tables {
  ColumnTable trace{TraceColumns()};
  ColumnTable foot{FootColumns()};
};
Tables TraceRowsOf(const ModeRun& run, const TrackResult& r) {
  Tables tables;
  ModeTraceRows(run, r, tables.trace, tables.foot);
  return tables;
}

void ExpectSameRow(const Table2& table, const std::string& a, const std::string& b) {
  const Table2Row* row_a = table.Find(a);
  const Table2Row* row_b = table.Find(b);
  ASSERT_NE(row_a, nullptr) << a;
  ASSERT_NE(row_b, nullptr) << b;
  for (int j = 0; j < kLegJoints; ++j) {
    EXPECT_EQ(row_a->joints[j].mean, row_b->joints[j].mean) << a << " " << kLegJointNames[j];
    EXPECT_EQ(row_a->joints[j].std, row_b->joints[j].std) << a << " " << kLegJointNames[j];
  }
}

// A copy of direct runs on the same plant, seed and steps as direct: every number of its rows,
// and every cell of its trace and foot tables, is direct's.
void ExpectTheCopyIsDirect(const ExperimentConfig& config, bool on_the_stand) {
  const std::vector<ExternalMode> external = {Mine()};
  const TrackResult r = RunTrackExperiment(config, {}, external);
  ASSERT_EQ(r.runs.size(), 2u);
  EXPECT_TRUE(r.runs[0].external.empty());
  EXPECT_EQ(r.runs[1].external, "mine");
  EXPECT_EQ(ModeInfo(r.runs[0]).name, "direct");
  EXPECT_EQ(ModeInfo(r.runs[1]).name, "mine");
  EXPECT_EQ(ModeInfo(r.runs[1]).label, "mine");
  EXPECT_FALSE(ModeInfo(r.runs[1]).feed_forward);
  EXPECT_EQ(&ContextFor(r, r.runs[1]), &r.context);

  const Table2 table = ComputeTable2(r);
  ExpectSameRow(table, "L2(Des,Dir)", "L2(Des,mine)");
  ExpectSameRow(table, "Linf(Des,Dir)", "Linf(Des,mine)");
  EXPECT_EQ(table.Find("L2(Pwl,mine)"), nullptr);
  const FootRow* direct = table.FindFoot("direct");
  const FootRow* mine = table.FindFoot("mine");
  ASSERT_NE(direct, nullptr);
  ASSERT_NE(mine, nullptr);
  EXPECT_TRUE(mine->parameters.empty());
  EXPECT_EQ(mine->l2_cm.mean, direct->l2_cm.mean);
  EXPECT_EQ(mine->l2_cm.std, direct->l2_cm.std);
  EXPECT_EQ(mine->linf_cm.mean, direct->linf_cm.mean);
  EXPECT_EQ(mine->linf_cm.std, direct->linf_cm.std);
  ASSERT_EQ(table.stand.has_value(), on_the_stand);
  if (table.stand) {
    ASSERT_EQ(table.stand->modes.size(), 2u);
    EXPECT_EQ(table.stand->modes[1].mode, "mine");
    EXPECT_EQ(table.stand->modes[1].slip_mm, table.stand->modes[0].slip_mm);
    EXPECT_EQ(table.stand->modes[1].peak_fz_n, table.stand->modes[0].peak_fz_n);
  }

  const Tables a = TraceRowsOf(r.runs[0], r);
  const Tables b = TraceRowsOf(r.runs[1], r);
  const auto period = static_cast<size_t>(r.period);
  EXPECT_EQ(a.trace.rows(), period * r.steps * kLegJoints);
  EXPECT_EQ(a.foot.rows(), period * r.steps);
  // Every column, the numeric ones and the joint names: a variant compares type and values.
  EXPECT_EQ(a.trace.columns, b.trace.columns);
  EXPECT_EQ(a.foot.columns, b.foot.columns);
}

TEST(ExternalModes, ACopyOfDirectIsDirectOnTheModelPlant) {
  ExpectTheCopyIsDirect(QuickModelPlant(), false);
}

TEST(ExternalModes, ACopyOfDirectIsDirectOnTheSimulatedLeg) {
  ExpectTheCopyIsDirect(QuickSimPlant(), false);
}

TEST(ExternalModes, ACopyOfDirectIsDirectOnTheStand) {
  ExpectTheCopyIsDirect(
      LoadExperimentConfig(
          std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/track_stand.yaml",
          {"warmup_steps=1", "steps=2", "controller.modes=[direct]",
           "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"}),
      true);
}

// The external mode's columns as they arrive (trace: step, tick, joint, then doubles).
TEST(ExternalModes, TraceColumnsHoldTheTypesOfTheirCells) {
  const std::vector<ExternalMode> external = {Mine()};
  const TrackResult r = RunTrackExperiment(QuickModelPlant(), {}, external);
  const Tables t = TraceRowsOf(r.runs[1], r);
  ASSERT_EQ(t.trace.columns.size(), t.trace.names.size());
  EXPECT_TRUE(std::holds_alternative<std::vector<long>>(t.trace.columns[0]));
  EXPECT_TRUE(std::holds_alternative<std::vector<long>>(t.trace.columns[1]));
  EXPECT_TRUE(std::holds_alternative<std::vector<std::string>>(t.trace.columns[2]));
  for (size_t c = 3; c < t.trace.columns.size(); ++c) {
    EXPECT_TRUE(std::holds_alternative<std::vector<double>>(t.trace.columns[c])) << c;
  }
  const auto& joints = std::get<std::vector<std::string>>(t.trace.columns[2]);
  ASSERT_GE(joints.size(), 3u);
  EXPECT_EQ(joints[0], "rotator");
  EXPECT_EQ(joints[1], "abductor");
  EXPECT_EQ(joints[2], "knee");
  // The desired column is the desired cycle, tick by tick.
  const auto& desired = std::get<std::vector<double>>(t.trace.columns[3]);
  for (size_t i = 0; i < desired.size(); ++i) {
    ASSERT_EQ(desired[i], r.context.desired[(i / kLegJoints) % r.period][i % kLegJoints]) << i;
  }
}

// A CSV file's cells by row (no quoting: track's files have none).
std::vector<std::vector<std::string>> ReadCsv(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream cells_in(line);
    std::string cell;
    while (std::getline(cells_in, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    rows.push_back(cells);
  }
  return rows;
}

// What the file holds, read back, is what the table holds, cell for cell.
void ExpectFileIsTable(const fs::path& path, const ColumnTable& table) {
  const auto rows = ReadCsv(path);
  ASSERT_EQ(rows.size(), table.rows() + 1) << path;
  EXPECT_EQ(rows[0], table.names) << path;
  for (size_t c = 0; c < table.columns.size(); ++c) {
    for (size_t i = 0; i < table.rows(); ++i) {
      const std::string& cell = rows[i + 1].at(c);
      if (const auto* d = std::get_if<std::vector<double>>(&table.columns[c])) {
        const double read = std::strtod(cell.c_str(), nullptr);
        if (std::isnan((*d)[i])) {
          ASSERT_TRUE(std::isnan(read)) << path << " " << table.names[c] << " row " << i;
        } else {
          ASSERT_EQ(read, (*d)[i]) << path << " " << table.names[c] << " row " << i;
        }
      } else if (const auto* l = std::get_if<std::vector<long>>(&table.columns[c])) {
        ASSERT_EQ(std::stol(cell), (*l)[i]) << path << " " << table.names[c] << " row " << i;
      } else {
        ASSERT_EQ(cell, std::get<std::vector<std::string>>(table.columns[c])[i])
            << path << " " << table.names[c] << " row " << i;
      }
    }
  }
}

TEST(ExternalModes, TheTablesInMemoryAreTheFilesCells) {
  const fs::path dir = fs::temp_directory_path() / "leglab_external_modes_test";
  fs::remove_all(dir);
  const ExperimentConfig config = QuickSimPlant();
  const std::vector<ExternalMode> external = {Mine()};
  const TrackResult r = RunTrackExperiment(config, {}, external);
  {
    OutputDir out(dir, TrackOutputPrefixes(std::vector<std::string>{"mine"}));
    for (const ModeRun& run : r.runs) WriteModeOutputs(run, r, out);
    WriteTrackTables(r, ComputeTable2(r), config, out);
    out.Commit();
  }
  for (const ModeRun& run : r.runs) {
    const std::string mode(ModeInfo(run).name);
    const Tables t = TraceRowsOf(run, r);
    ExpectFileIsTable(dir / ("trace_" + mode + ".csv"), t.trace);
    ExpectFileIsTable(dir / ("foot_" + mode + ".csv"), t.foot);
  }
  // Not feed-forward: its learning curve is written; and its rows are in table2.json.
  EXPECT_TRUE(fs::exists(dir / "mine_learning.csv"));
  std::ifstream json(dir / "table2.json");
  std::stringstream text;
  text << json.rdbuf();
  EXPECT_NE(text.str().find("\"L2(Des,mine)\""), std::string::npos);
  EXPECT_NE(text.str().find("\"mine\""), std::string::npos);
  fs::remove_all(dir);
}

// A bad external mode is refused, naming it, before anything runs: no configured mode's run
// reaches the sink and no make is called.
// Makes every mode of `external` that has a make function set `made` when it is called.
void RecordMakes(std::vector<ExternalMode>& external, bool& made) {
  for (ExternalMode& mode : external) {
    if (!mode.make) continue;
    mode.make = [&made](const ControllerContext& context) -> std::unique_ptr<JointController> {
      made = true;
      return std::make_unique<MyDirect>(context);
    };
  }
}

void ExpectRefused(std::vector<ExternalMode> external, const std::string& named) {
  bool made = false;
  RecordMakes(external, made);
  int runs = 0;
  try {
    RunTrackExperiment(
        QuickModelPlant(), [&runs](const TrackResult&, ModeRun&&) { ++runs; }, external);
    ADD_FAILURE() << "accepted " << named;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("controller '" + named + "'"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(made) << named;
  EXPECT_EQ(runs, 0) << named;
}

TEST(ExternalModes, BadNamesAreRefusedBeforeAnythingRuns) {
  ExpectRefused({Mine("ok"), Mine("direct")}, "direct");
  ExpectRefused({Mine("time_shift")}, "time_shift");
  ExpectRefused({Mine("ok"), Mine("My Ctrl")}, "My Ctrl");
  ExpectRefused({Mine("")}, "");
  ExpectRefused({Mine("dir/mine")}, "dir/mine");
  ExpectRefused({Mine(std::string(65, 'a'))}, std::string(65, 'a'));
  ExpectRefused({Mine("mine"), Mine("ok"), Mine("mine")}, "mine");
  ExpectRefused({Mine("floor")}, "floor");
  ExpectRefused({Mine("ok"), ExternalMode{"mine", nullptr}}, "mine");
}

TEST(ExternalModes, ANameOf64CharactersIsAccepted) {
  const std::string name(64, 'a');
  const std::vector<ExternalMode> external = {Mine(name)};
  const TrackResult r = RunTrackExperiment(QuickModelPlant(), {}, external);
  ASSERT_EQ(r.runs.size(), 2u);
  EXPECT_EQ(ModeInfo(r.runs[1]).name, name);
}

// (warmup_steps + steps) x t_step_ticks per external run, added to what the config plans,
// must stay within kMaxTotalTicks.
TEST(ExternalModes, TooManyTicksAreRefusedBeforeAnythingRuns) {
  const ExperimentConfig config = LoadExperimentConfig(
      kTrack, {"plant=model", "warmup_steps=0", "steps=1000000", "controller.modes=[direct]",
               "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"});
  const long long per_run = 1000000LL * config.track.t_step_ticks;
  EXPECT_EQ(PlannedTrackTicks(config, 3), config.planned_ticks + 3 * per_run);
  // The most external runs that fit, and one more.
  const long long fit = (kMaxTotalTicks - config.planned_ticks) / per_run;
  std::vector<ExternalMode> external;
  for (long long i = 0; i <= fit; ++i) external.push_back(Mine("m" + std::to_string(i)));
  bool made = false;
  RecordMakes(external, made);
  int runs = 0;
  try {
    RunTrackExperiment(
        config, [&runs](const TrackResult&, ModeRun&&) { ++runs; }, external);
    ADD_FAILURE() << "accepted " << external.size() << " external runs";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(PlannedTrackTicks(config, fit + 1))),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(made);
  EXPECT_EQ(runs, 0);
}

struct ControllerFailure : std::exception {
  const char* what() const noexcept override { return "my controller failed"; }
};

class FailsAtTick final : public JointController {
 public:
  explicit FailsAtTick(const ControllerContext& context) : desired_(context.desired) {}
  LegAngles Update(long tick, const LegAngles& /*measured_deg*/) override {
    if (tick == 30) throw ControllerFailure();
    return CycleAt(desired_, tick);
  }
  std::string_view name() const override { return "fails"; }

 private:
  DesiredCycle desired_;
};

TEST(ExternalModes, WhatTheControllerOrItsMakeThrowsPropagates) {
  const std::vector<ExternalMode> fails = {{"fails", [](const ControllerContext& context) {
                                              return std::make_unique<FailsAtTick>(context);
                                            }}};
  EXPECT_THROW(RunTrackExperiment(QuickModelPlant(), {}, fails), ControllerFailure);
  const std::vector<ExternalMode> make_fails = {
      {"make_fails", [](const ControllerContext&) -> std::unique_ptr<JointController> {
         throw std::domain_error("no such controller");
       }}};
  EXPECT_THROW(RunTrackExperiment(QuickModelPlant(), {}, make_fails), std::domain_error);
  // A make that returns no controller is the caller's error, named.
  const std::vector<ExternalMode> none = {
      {"none", [](const ControllerContext&) { return std::unique_ptr<JointController>(); }}};
  try {
    RunTrackExperiment(QuickModelPlant(), {}, none);
    ADD_FAILURE() << "ran without a controller";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("controller 'none'"), std::string::npos) << e.what();
  }
}

// The prefixes own an external mode's files: a folder where one would go is refused before
// the run, as for a registered mode's.
TEST(ExternalModes, TheOutputPrefixesOwnItsFiles) {
  const fs::path dir = fs::temp_directory_path() / "leglab_external_prefixes_test";
  fs::remove_all(dir);
  const std::vector<std::string> names = {"mine"};
  const std::vector<std::string> prefixes = TrackOutputPrefixes(names);
  for (const std::string file : {"trace_mine.csv", "foot_mine.csv", "mine_learning.csv"}) {
    bool owned = false;
    for (const std::string& prefix : prefixes) owned = owned || file.rfind(prefix, 0) == 0;
    EXPECT_TRUE(owned) << file;
  }
  fs::create_directories(dir / "mine_learning.csv");
  EXPECT_NO_THROW(CheckOutFolder(dir, TrackOutputPrefixes()));
  EXPECT_THROW(CheckOutFolder(dir, prefixes), InputError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace leglab::experiments
