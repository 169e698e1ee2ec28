#pragma once

// The run-size budget: how much a config asks the programs to simulate, checked before
// anything runs (kMaxTicksPerRun, kMaxTotalTicks, kMaxIdentificationWork in config.h).
#include "leglab/experiments/config.h"

namespace leglab::experiments {

/// The ticks `config`'s run simulates at most: the step tests (unless `tracks` and a model is
/// given), then, when `tracks`, one run per mode and per searched candidate plus the best
/// one's rerun, and the walk the walk-fitted models are fitted to. Throws InputError when one
/// tracking run, the whole run or one joint's identification is over its budget.
long long PlannedTicks(const ExperimentConfig& config, bool tracks);

}  // namespace leglab::experiments
