#pragma once

#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <string>
#include <thread>

namespace leglab {

/// How a program shows its progress on stderr (stdout carries only the tables).
enum class ProgressStyle {
  kOff,    ///< nothing (--quiet, or stderr is not a terminal and --progress was not given)
  kBar,    ///< a bar with the share done and an estimate of the time left, redrawn in place
  kLines,  ///< a plain line every 2 s (--progress: for logs and CI)
};

/// Adds `ticks` simulated ticks to this process's progress count. Thread-safe and cheap; the
/// run loops call it once per step or cycle. Throws RunStopped when a stop was requested. The count
/// is a side channel for the display only: no result depends on it (which is why it may be
/// process-wide).
void CountProgressTicks(long ticks);

/// Thrown by CountProgressTicks once RequestStop has asked for a stop: the run unwinds (an
/// OutputDir on the way removes its staging folder and lock) instead of running to its end.
class RunStopped : public std::exception {
 public:
  explicit RunStopped(int signal) : signal_(signal) {}
  int signal() const { return signal_; }  ///< what RequestStop was given
  const char* what() const noexcept override { return "the run was stopped by a signal"; }

 private:
  int signal_;
};

/// Asks every run of this process to stop at its next CountProgressTicks, which throws
/// RunStopped(signal); 0 withdraws the request. Async-signal-safe (one atomic store): for an
/// embedding that catches signals itself (the Python package's run_track), where the programs
/// use InstallInterruptCleanup.
void RequestStop(int signal);

/// The signal of the pending stop request, 0 when none.
int StopRequested();

/// The ticks CountProgressTicks has added up in this process so far.
long long CountedProgressTicks();

/// Names what the program does now, e.g. "writing trace_direct.csv"; shown beside the share.
void SetProgressPhase(const std::string& phase);

/// Replaces the plan the display measures against, for a program whose work is known only
/// once its input is read (a log fit): `units` of work called `unit` in the plain lines (e.g.
/// "fit-ticks"), counted from zero by CountProgressTicks from now on, the time left
/// extrapolated from the rate since this call.
void ReplanProgress(long long units, const std::string& unit);

/// Marks the work done: the display stops drawing and clears its bar, so that the tables
/// printed next stand alone on a terminal.
void FinishProgress();

/// Shows progress on stderr while it lives, from a thread of its own: the ticks counted by
/// CountProgressTicks against `planned_ticks` (an upper bound), the time left extrapolated from
/// the rate so far, and the phase. With kLines a line appears at the start and then at least
/// every 2 s, so a run is never silent for long, whatever it does.
class ProgressDisplay {
 public:
  ProgressDisplay(std::string program, ProgressStyle style, long long planned_ticks);
  ~ProgressDisplay();
  ProgressDisplay(const ProgressDisplay&) = delete;
  ProgressDisplay& operator=(const ProgressDisplay&) = delete;

 private:
  void Loop();
  // Draws one line (or redraws the bar); false once the run has finished.
  bool Draw();

  std::string program_;
  ProgressStyle style_;
  long long planned_ticks_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace leglab
