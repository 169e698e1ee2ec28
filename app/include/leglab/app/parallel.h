#pragma once

#include <functional>

#include "leglab/core/config_keys.h"

namespace leglab {

/// The declared range of a worker-thread count (the programs' --threads from 1, the Python
/// package's threads from 0: one per core).
inline constexpr KeyDoc kThreadsDoc{
    .min = 0, .max = 4096, .description = "worker threads (0: one per core)"};

/// Worker threads for `requested` (--threads): itself when positive, else one per core.
int ThreadCount(int requested);

/// Calls fn(i) for i = 0..n-1 on up to ThreadCount(threads) threads (the calling thread is
/// one of them). Each i must write only its own results, so the outcome does not depend on
/// the schedule or the thread count. The exception thrown by fn(i) with the lowest i that threw
/// is rethrown after every thread has stopped (so it does not depend on the schedule either).
void ParallelFor(int n, int threads, const std::function<void(int)>& fn);

}  // namespace leglab
