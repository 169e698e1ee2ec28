#pragma once
// The side-by-side benchmarks' one own flag, their median and their main, shared by the
// benchmark programs.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace leglab::benchmarks {

/// The median of `values`, at least one: of an even count, the mean of the two middle ones.
inline double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

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

/// A side-by-side benchmark's main: takes --rounds (default `fallback`), runs the registered
/// Google Benchmark cases the other flags select, then `report(rounds)` (the interleaved rounds,
/// printed as ratios). Returns main's status: 1 on an argument neither knows.
template <typename Report>
int RunThenReport(int argc, char** argv, int fallback, Report report) {
  const int rounds = TakeRoundsFlag(argc, argv, fallback);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  report(rounds);
  return 0;
}

}  // namespace leglab::benchmarks
