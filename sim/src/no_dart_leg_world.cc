// A build without DART (LEGLAB_WITH_DART off): compiled instead of dart_leg_world.cc, so that
// sim.engine: dart is refused as bad input (kNoDart) where it would have run.

#include <memory>
#include <stdexcept>
#include <string>

#include "leglab/sim/sim_config.h"
#include "physics_world.h"

namespace leglab::sim {

std::unique_ptr<PhysicsWorld> MakeDartWorld(const LegDescription& /*leg*/,
                                            const StandConfig& /*stand*/) {
  throw std::invalid_argument(std::string(kNoDart));
}

bool BuiltWithDart() { return false; }

}  // namespace leglab::sim
