// track: regenerates the paper's Table 2. Drives the leg through the half-elliptical walk
// (or a desired.csv) with each controller mode and compares desired, approximated and actual
// trajectories in joint space and foot space. Writes table2.json, table2.md,
// trace_<mode>.csv, foot_<mode>.csv, shift_search.csv and a learning mode's
// <mode>_learning.csv into --out.
#include <iostream>
#include <optional>

#include "leglab/app/output.h"
#include "leglab/experiments/program.h"
#include "leglab/experiments/tables.h"
#include "leglab/experiments/track.h"
#include "leglab/experiments/writers.h"

int main(int argc, char** argv) {
  using namespace leglab;
  using namespace leglab::experiments;
  return RunProgram("track", "Table 2: track the half-ellipse walk with each controller",
                    ConfigScope{"track", {}}, TrackOutputs(), argc, argv,
                    [](const ProgramArgs& args, const ExperimentConfig& config) {
                      OutputDir out(args.out_dir, TrackOutputPrefixes());
                      // One mode's run at a time: written and reduced to its table rows, then
                      // dropped, so memory holds one run however many modes there are.
                      std::optional<Table2> table;
                      const TrackResult result =
                          RunTrackExperiment(config, [&](const TrackResult& r, ModeRun&& run) {
                            if (!table) table = BeginTable2(r);
                            AddModeToTable2(*table, run, r);
                            WriteModeOutputs(run, r, out);
                          });
                      if (!table) table = BeginTable2(result);
                      const std::string tables = WriteTrackTables(result, *table, config, out);
                      WriteConfigFile("track", config, out);
                      out.Commit();
                      std::cout << tables;
                    });
}
