#pragma once
// The side-by-side benchmarks' one own flag, shared by every benchmark program.

#include <algorithm>
#include <cstdlib>
#include <cstring>

namespace leglab::benchmarks {

/// Takes every `--rounds=N` out of argv (before Google Benchmark sees the arguments) and
/// returns the last N given (at least 1), or `fallback` when there is none.
inline int TakeRoundsFlag(int& argc, char** argv, int fallback) {
  int rounds = fallback;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--rounds=", 9) == 0) {
      rounds = std::max(1, std::atoi(argv[i] + 9));
    } else {
      argv[kept++] = argv[i];
    }
  }
  argc = kept;
  return rounds;
}

}  // namespace leglab::benchmarks
