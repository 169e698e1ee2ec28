#pragma once

#include <filesystem>

namespace leglab {

/// The folder of leglab's run-time data: `robots/<name>/`, `experiments/configs/` and
/// `data/servo_logs/`.
/// It is the environment variable LEGLAB_DATA_DIR when that is set and not empty, else
/// `share/leglab` beside the running program's `bin/`, i.e.
/// `<directory of /proc/self/exe>/../share/leglab`: `<prefix>/share/leglab` for an installed
/// program, `<build>/share/leglab` (links to the source folders) in a build tree. A program
/// of your own that links leglab::app but is not installed beside leglab's programs
/// sets LEGLAB_DATA_DIR or names robots by path. Throws std::runtime_error when the running
/// program cannot be found (no /proc).
std::filesystem::path DataDir();

}  // namespace leglab
