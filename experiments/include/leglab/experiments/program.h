#pragma once

#include <functional>
#include <span>
#include <string>
#include <vector>

#include "leglab/app/output_docs.h"
#include "leglab/app/program.h"
#include "leglab/experiments/config.h"

namespace leglab::experiments {

/// Parses the flags, loads the config (keys outside `scope` rejected, see ConfigScope) and runs
/// `body` while a ProgressDisplay shows its progress on stderr (a bar on a terminal, plain lines
/// with --progress, nothing with --quiet). Bad input (flags, config, robot, URDF, CSV, an
/// unreachable locus: InputError, std::invalid_argument, std::domain_error) prints "<program>:
/// error: <message>" on one line and returns 2; a failure to write the results prints "<program>:
/// failed: <message>" and returns 1; anything else that escapes is ours and prints "<program>:
/// internal error: <message>" and returns 1; success returns 0.
int RunProgram(const std::string& program, const std::string& description, const ConfigScope& scope,
               int argc, char** argv,
               const std::function<void(const ProgramArgs&, const ExperimentConfig&)>& body);

/// RunProgram for a program that declares the files it writes: `--list-outputs` prints them
/// (OutputsMarkdown) and exits.
int RunProgram(const std::string& program, const std::string& description, const ConfigScope& scope,
               std::span<const OutputDoc> outputs, int argc, char** argv,
               const std::function<void(const ProgramArgs&, const ExperimentConfig&)>& body);

/// RunProgram for a program that uses every config key.
int RunProgram(const std::string& program, const std::string& description, int argc, char** argv,
               const std::function<void(const ProgramArgs&, const ExperimentConfig&)>& body);

}  // namespace leglab::experiments
