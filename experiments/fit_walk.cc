// fit_walk: recovers the walk behind the paper's Table 2 from its direct-method row alone
// (FitWalk) on the config's plant (as shipped: track.yaml), t_step its track.t_step_ticks.
// Writes walk_fit.json and walk_fit.md into --out and prints the latter.
#include <iostream>
#include <string>
#include <vector>

#include "leglab/app/output.h"
#include "leglab/experiments/program.h"
#include "leglab/experiments/walk_fit.h"
#include "leglab/experiments/writers.h"

int main(int argc, char** argv) {
  using namespace leglab;
  using namespace leglab::experiments;
  return RunProgram(
      "fit_walk", "Fit the walk's unknowns to the paper's direct-method row of Table 2",
      ConfigScope{"fit_walk", {}}, WalkFitOutputs(), argc, argv,
      [](const ProgramArgs& args, const ExperimentConfig& config) {
        if (!config.track.desired_csv.empty()) {
          throw InputError(
              "desired.csv: fit_walk fits the half-elliptical locus; remove "
              "desired.csv from the config");
        }
        // A --set of a fitted key would be silently replaced by the fit: refuse it.
        for (const std::string& o : args.overrides) {
          const std::string key = o.substr(0, o.find('='));
          if (IsFittedWalkKey(key)) {
            throw InputError("--set " + key +
                             ": fit_walk fits this key; set it in the config of a "
                             "track run instead");
          }
        }
        OutputDir out(args.out_dir, {"walk_fit.", ConfigFileName("fit_walk")});
        // The direct mode alone, its model fixed (direct never uses it: no identification).
        std::vector<std::string> overrides = args.overrides;
        overrides.insert(overrides.end(),
                         {"controller.modes=[direct]", "track.search_shift=false",
                          "model={v_max_deg_per_tick: 2.5, theta0_deg: 7.0, lag_ticks: 4, "
                          "accel_ticks: 6}"});
        const ExperimentConfig full = LoadExperimentConfig(args.config_path, overrides);

        const WalkFitReport report = FitWalk(full, config.threads);
        const std::string md = WalkFitMarkdown(report);
        WriteTextFile(out.Path("walk_fit.json"),
                      WalkFitJson(report, args.config_path, args.overrides));
        WriteTextFile(out.Path("walk_fit.md"), md);
        WriteConfigFile("fit_walk", config, out);
        out.Commit();
        std::cout << md;
      });
}
