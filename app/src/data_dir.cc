#include "leglab/app/data_dir.h"

#include <cstdlib>
#include <stdexcept>
#include <system_error>

#ifndef LEGLAB_DATA_DIR_FROM_BIN
#error "LEGLAB_DATA_DIR_FROM_BIN (bin/ to share/leglab, e.g. ../share/leglab) is set by CMake"
#endif

namespace leglab {

namespace fs = std::filesystem;

fs::path DataDir() {
  if (const char* env = std::getenv("LEGLAB_DATA_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  // The executable itself, symbolic links resolved: a link to an installed program still finds
  // the data beside the program's real location.
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("DataDir: cannot read /proc/self/exe: " + ec.message());
  return (exe.parent_path() / LEGLAB_DATA_DIR_FROM_BIN).lexically_normal();
}

}  // namespace leglab
