#include "leglab/experiments/program.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>
#include <new>
#include <stdexcept>
#include <system_error>

#include "leglab/experiments/output.h"
#include "leglab/experiments/progress.h"

namespace leglab::experiments {

void AddListKeysFlag(CLI::App& app, const std::function<std::string()>& table) {
  app.add_flag_callback(
      "--list-keys",
      [table] {
        std::cout << table();
        throw CLI::Success();
      },
      "print the config keys this program reads (a Markdown table: key, type, default, range, "
      "unit, description) and exit");
}

int ReportErrors(const std::string& program, const std::function<void()>& body) {
  try {
    body();
    return 0;
  } catch (const InputError& e) {
    std::cerr << program << ": error: " << e.what() << '\n';
  } catch (const std::invalid_argument& e) {
    std::cerr << program << ": error: " << e.what() << '\n';
  } catch (const std::domain_error& e) {
    std::cerr << program << ": error: " << e.what() << '\n';
  } catch (const OutputError& e) {
    std::cerr << program << ": failed: " << e.what() << '\n';
    return 1;
  } catch (const std::filesystem::filesystem_error& e) {
    std::cerr << program << ": failed: " << e.what() << '\n';
    return 1;
  } catch (const std::bad_alloc&) {
    std::cerr << program << ": internal error: out of memory (std::bad_alloc)\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << program << ": internal error: " << e.what() << '\n';
    return 1;
  } catch (...) {
    std::cerr << program << ": internal error: an unknown exception\n";
    return 1;
  }
  return 2;
}

int RunProgram(const std::string& program, const std::string& description, const ConfigScope& scope,
               int argc, char** argv,
               const std::function<void(const ProgramArgs&, const ExperimentConfig&)>& body) {
  CLI::App app(description, program);
  ProgramArgs args;
  app.add_option("--config", args.config_path, "experiment config (YAML)")->required();
  app.add_option("--out", args.out_dir, "folder for the results")->required();
  app.add_option("--threads", args.threads,
                 "worker threads (default: one per core); results do not depend on it")
      ->check(CLI::PositiveNumber);
  CLI::Option* progress = app.add_flag(
      "--progress", args.progress,
      "plain progress lines on stderr (for logs and CI); default: a bar on a terminal");
  app.add_flag("--quiet", args.quiet, "no progress on stderr")->excludes(progress);
  app.add_option("--set", args.overrides,
                 "override a config key, e.g. --set servo.delay_ms=48 (YAML value; repeatable)");
  AddListKeysFlag(app, [&scope] { return KeyTableMarkdown(ExperimentKeys(scope)); });
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, or --list-keys printed the keys
  } catch (const CLI::ParseError& e) {
    std::cerr << program << ": error: " << e.what() << " (see --help)\n";
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
