// track: regenerates the paper's Table 2. Drives the leg through the half-elliptical walk
// (or a desired.csv) with each controller mode and compares desired, approximated and actual
// trajectories in joint space and foot space. Writes table2.json, table2.md,
// trace_<mode>.csv, foot_<mode>.csv, shift_search.csv and a learning mode's
// <mode>_learning.csv into --out.
#include <iostream>

#include "leglab/experiments/program.h"
#include "leglab/experiments/tables.h"
#include "leglab/experiments/track.h"
#include "leglab/experiments/writers.h"

int main(int argc, char** argv) {
  using namespace leglab::experiments;
  return RunProgram("track", "Table 2: track the half-ellipse walk with each controller", argc,
                    argv, [](const ProgramArgs& args, const ExperimentConfig& config) {
                      OutputDir out(args.out_dir, TrackOutputPrefixes());
                      const TrackResult result = RunTrackExperiment(config);
                      const std::string tables =
                          WriteTrackOutputs(result, ComputeTable2(result), out);
                      out.Commit();
                      std::cout << tables;
                    });
}
