// identify: regenerates the paper's Table 1 from the simulated leg. Runs the step test of
// eq. 1 on each joint in turn, fits the joint model to what the plant did, and writes
// table1.json, table1.md and step_<joint>_<theta>.csv into --out; with a `logs` section it
// fits recorded servo logs instead (log_fit.json, log_fit.md, log_<motor>_<name>.csv). Either
// way identify_config.yaml holds the keys it ran with.
#include <iostream>
#include <string>
#include <vector>

#include "leglab/app/output.h"
#include "leglab/experiments/program.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/writers.h"
#include "leglab/servo/log_fit.h"

int main(int argc, char** argv) {
  using namespace leglab;
  using namespace leglab::experiments;
  return RunProgram("identify", "Table 1: identify the joint model from step responses",
                    kIdentifyScope, IdentifyOutputs(), argc, argv,
                    [](const ProgramArgs& args, const ExperimentConfig& config) {
                      if (config.logs.given) {
                        // Recorded servo logs instead of step tests on the plant.
                        std::vector<std::string> owned = kLogFitOutputPrefixes;
                        owned.push_back(ConfigFileName("identify"));
                        OutputDir out(args.out_dir, owned);
                        const std::string table = RunLogFit(config.logs, out, config.threads);
                        WriteConfigFile("identify", config, out);
                        out.Commit();
                        std::cout << table;
                        return;
                      }
                      OutputDir out(args.out_dir, {"table1.", "step_", ConfigFileName("identify")});
                      const Robot robot = LoadRobot(config.sim.urdf_path);
                      const auto joints = IdentifyLeg(config, robot);
                      const std::string table = WriteIdentifyOutputs(joints, config, out);
                      WriteConfigFile("identify", config, out);
                      out.Commit();
                      std::cout << table;
                    });
}
