#include "leglab/app/progress.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace leglab {
namespace {

using Clock = std::chrono::steady_clock;

// The side channel between the run loops and the display (see CountProgressTicks). Never
// destroyed: the display thread may read it while the process exits.
struct ProgressState {
  std::atomic<long long> ticks{0};
  std::atomic<bool> finished{false};
  std::mutex mutex;  // guards phase, and stderr against the display's redraws
  std::string phase = "starting";
  // Set by ReplanProgress (guarded by mutex): the plan that replaces the display's own.
  long long planned = 0;
  std::string unit = "ticks";
  Clock::time_point plan_start;
  bool replanned = false;
  bool bar_drawn = false;
};

ProgressState& State() {
  static auto* state = new ProgressState;
  return *state;
}

std::string Duration(double seconds) {
  const long s = std::lround(seconds);
  char buffer[48];
  if (s >= 3600) {
    std::snprintf(buffer, sizeof buffer, "%ldh%02ldm", s / 3600, s / 60 % 60);
  } else if (s >= 60) {
    std::snprintf(buffer, sizeof buffer, "%ldm%02lds", s / 60, s % 60);
  } else {
    std::snprintf(buffer, sizeof buffer, "%lds", s);
  }
  return buffer;
}

// Clears a drawn bar; the caller holds State().mutex.
void ClearBar() {
  if (!State().bar_drawn) return;
  std::fputs("\r\033[K", stderr);
  std::fflush(stderr);
  State().bar_drawn = false;
}

}  // namespace

namespace {
// RequestStop's flag: a plain static atomic, so that a signal handler only stores to it.
std::atomic<int> stop_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);
}  // namespace

void RequestStop(int signal) { stop_signal.store(signal, std::memory_order_relaxed); }

int StopRequested() { return stop_signal.load(std::memory_order_relaxed); }

void CountProgressTicks(long ticks) {
  State().ticks.fetch_add(ticks, std::memory_order_relaxed);
  if (const int signal = StopRequested(); signal != 0) throw RunStopped(signal);
}

long long CountedProgressTicks() { return State().ticks.load(std::memory_order_relaxed); }

void SetProgressPhase(const std::string& phase) {
  const std::lock_guard<std::mutex> lock(State().mutex);
  State().phase = phase;
}

void ReplanProgress(long long units, const std::string& unit) {
  const std::lock_guard<std::mutex> lock(State().mutex);
  State().ticks = 0;
  State().planned = std::max(1LL, units);
  State().unit = unit;
  State().plan_start = Clock::now();
  State().replanned = true;
}

void FinishProgress() {
  const std::lock_guard<std::mutex> lock(State().mutex);
  State().finished = true;
  ClearBar();
}

ProgressDisplay::ProgressDisplay(std::string program, ProgressStyle style, long long planned_ticks)
    : program_(std::move(program)),
      style_(style),
      planned_ticks_(std::max(0LL, planned_ticks)),
      start_(Clock::now()) {
  if (style_ == ProgressStyle::kOff) return;
  // The first line before any work, on this thread: a run shorter than the redraw period still
  // says what it plans, and the first line is always the 0 % one, however loaded the machine.
  Draw();
  thread_ = std::thread([this] { Loop(); });
}

ProgressDisplay::~ProgressDisplay() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  const std::lock_guard<std::mutex> lock(State().mutex);
  ClearBar();
}

void ProgressDisplay::Loop() {
  const auto period = style_ == ProgressStyle::kBar ? std::chrono::milliseconds(250)
                                                    : std::chrono::milliseconds(2000);
  std::unique_lock<std::mutex> wait_lock(mutex_);
  while (!wake_.wait_for(wait_lock, period, [this] { return stop_; })) {
    if (!Draw()) return;
  }
}

bool ProgressDisplay::Draw() {
  const std::lock_guard<std::mutex> lock(State().mutex);
  if (State().finished) return false;
  const ProgressState& state = State();
  const long long planned = state.replanned ? state.planned : planned_ticks_;
  const long long done = std::min(state.ticks.load(), planned);
  const double share = planned > 0 ? static_cast<double>(done) / static_cast<double>(planned) : 0.0;
  const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
  // The rate since the plan began: a replanned run's earlier work (reading) is not its rate.
  const double planned_elapsed =
      state.replanned ? std::chrono::duration<double>(Clock::now() - state.plan_start).count()
                      : elapsed;
  const std::string left =
      done > 0 && planned_elapsed > 1.0
          ? "about " + Duration(planned_elapsed * (1.0 - share) / share) + " left"
          : "estimating the time left";
  char line[256];
  if (style_ == ProgressStyle::kBar) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(share * kWidth);
    const std::string bar = std::string(filled, '#') + std::string(kWidth - filled, '.');
    std::snprintf(line, sizeof line, "\r\033[K%s [%s] %3.0f%% %s, %s", program_.c_str(),
                  bar.c_str(), 100.0 * share, left.c_str(), State().phase.c_str());
    State().bar_drawn = true;
  } else {
    // Nothing planned yet (a log fit before it has read its logs): no share to state.
    const std::string of = planned > 0 ? " of " + std::to_string(planned) + " " + state.unit
                                       : " of work not yet known";
    std::snprintf(line, sizeof line, "%s: %.0f%%%s after %s, %s (%s)\n", program_.c_str(),
                  100.0 * share, of.c_str(), Duration(elapsed).c_str(), left.c_str(),
                  state.phase.c_str());
  }
  std::fputs(line, stderr);
  std::fflush(stderr);
  return true;
}

}  // namespace leglab
