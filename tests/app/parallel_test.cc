// ParallelFor: every index runs once, and the error rethrown does not depend on the schedule.
#include "leglab/app/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace leglab {
namespace {

TEST(ParallelForTest, RunsEveryIndexOnce) {
  std::vector<std::atomic<int>> runs(100);
  ParallelFor(100, 4, [&](int i) { ++runs[i]; });
  for (const std::atomic<int>& r : runs) EXPECT_EQ(r.load(), 1);
}

// Index 1 throws last in time (it waits first), index 6 at once: the error of index 1 is the
// one rethrown, and every index still runs.
TEST(ParallelForTest, RethrowsTheLowestIndexsErrorNotTheFirstInTime) {
  for (const int threads : {1, 2, 8}) {
    std::atomic<int> ran{0};
    try {
      ParallelFor(8, threads, [&](int i) {
        ++ran;
        if (i == 1) {
          std::this_thread::sleep_for(std::chrono::milliseconds(50));
          throw std::runtime_error("index 1");
        }
        if (i == 6) throw std::runtime_error("index 6");
      });
      ADD_FAILURE() << "nothing thrown";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "index 1") << threads << " threads";
    }
    EXPECT_EQ(ran.load(), 8);
  }
}

}  // namespace
}  // namespace leglab
