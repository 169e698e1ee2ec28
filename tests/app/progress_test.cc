// The progress display's plan: a program that knows its work only once it has read its input
// (a log fit) says so, then measures against the plan it gives (ReplanProgress).
#include <gtest/gtest.h>

#include <string>

#include "leglab/app/progress.h"

namespace {

using namespace leglab;

// The line a display draws at once when it starts (kLines), before any wait.
std::string FirstLine(long long planned_ticks) {
  testing::internal::CaptureStderr();
  { const ProgressDisplay display("prog", ProgressStyle::kLines, planned_ticks); }
  return testing::internal::GetCapturedStderr();
}

TEST(ProgressTest, NothingPlannedSaysSoThenAReplanIsTheMeasure) {
  EXPECT_EQ(FirstLine(0).rfind("prog: 0% of work not yet known after 0s", 0), 0u) << FirstLine(0);
  CountProgressTicks(7);
  ReplanProgress(200, "training ticks over 3 fits");
  EXPECT_EQ(CountedProgressTicks(), 0);  // counted from the plan on
  CountProgressTicks(50);
  EXPECT_EQ(CountedProgressTicks(), 50);
  const std::string line = FirstLine(6864);  // the display's own plan gives way to the replan
  EXPECT_EQ(line.rfind("prog: 25% of 200 training ticks over 3 fits after ", 0), 0u) << line;
}

}  // namespace
