#include "leglab/experiments/program.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <iostream>

#include "leglab/app/output.h"
#include "leglab/app/parallel.h"
#include "leglab/app/progress.h"

namespace leglab::experiments {

int RunProgram(const std::string& program, const std::string& description, const ConfigScope& scope,
               int argc, char** argv,
               const std::function<void(const ProgramArgs&, const ExperimentConfig&)>& body) {
  return RunProgram(program, description, scope, {}, argc, argv, body);
}

int RunProgram(const std::string& program, const std::string& description, const ConfigScope& scope,
               std::span<const OutputDoc> outputs, int argc, char** argv,
               const std::function<void(const ProgramArgs&, const ExperimentConfig&)>& body) {
  CLI::App app(description, program);
  ProgramArgs args;
  app.add_option("--config", args.config_path, "experiment config (YAML)")->required();
  app.add_option("--out", args.out_dir, "folder for the results")->required();
  app.add_option("--threads", args.threads,
                 "worker threads (default: one per core); results do not depend on it")
      ->check(CLI::Range(1, static_cast<int>(kThreadsDoc.max)));
  CLI::Option* progress = app.add_flag(
      "--progress", args.progress,
      "plain progress lines on stderr (for logs and CI); default: a bar on a terminal");
  app.add_flag("--quiet", args.quiet, "no progress on stderr")->excludes(progress);
  app.add_option("--set", args.overrides,
                 "override a config key, e.g. --set servo.delay_ms=48 (YAML value; repeatable)");
  AddListKeysFlag(app, [&scope] { return KeyTableMarkdown(ExperimentKeys(scope)); });
  if (!outputs.empty()) AddListOutputsFlag(app, outputs);
  RefuseEmptyValues(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, or --list-keys printed the keys
  } catch (const CLI::ParseError& e) {
    std::cerr << program << ": error: " << MessageLine(e.what()) << " (see --help)\n";
    return 2;
  }
  // Before any thread starts: an interruption removes the staging folder (OutputDir).
  InstallInterruptCleanup(program);
  return ReportErrors(program, [&] {
    ExperimentConfig config = LoadExperimentConfig(args.config_path, args.overrides, scope);
    config.threads = args.threads;
    const ProgressStyle style = args.quiet                     ? ProgressStyle::kOff
                                : args.progress                ? ProgressStyle::kLines
                                : ::isatty(STDERR_FILENO) != 0 ? ProgressStyle::kBar
                                                               : ProgressStyle::kOff;
    const ProgressDisplay display(program, style, config.planned_ticks);
    body(args, config);
  });
}

int RunProgram(const std::string& program, const std::string& description, int argc, char** argv,
               const std::function<void(const ProgramArgs&, const ExperimentConfig&)>& body) {
  return RunProgram(program, description, ConfigScope{program, {}}, argc, argv, body);
}

}  // namespace leglab::experiments
