#include "ode_world.h"

#include <ode/threading_impl.h>

#include <stdexcept>

namespace leglab::sim {

void EnsureOdeReady() {
  struct Runtime {
    Runtime() { dInitODE2(0); }
    ~Runtime() { dCloseODE(); }
    Runtime(const Runtime&) = delete;
    Runtime& operator=(const Runtime&) = delete;
  };
  static Runtime runtime;
  thread_local const bool thread_ready = dAllocateODEDataForThread(dAllocateMaskAll) != 0;
  if (!thread_ready) {
    throw std::runtime_error("leglab::sim: ODE could not allocate thread data");
  }
}

OdeWorld::OdeWorld()
    : threading_(dThreadingAllocateSelfThreadedImplementation()), world_(dWorldCreate()) {
  if (threading_ == nullptr || world_ == nullptr) {
    Release();
    throw std::runtime_error("leglab::sim: ODE could not create a world");
  }
  dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(threading_),
                                       threading_);
}

OdeWorld::~OdeWorld() { Release(); }

void OdeWorld::Release() noexcept {
  if (world_ != nullptr) {
    dWorldSetStepThreadingImplementation(world_, nullptr, nullptr);
    dWorldDestroy(world_);  // and its bodies and joints
  }
  if (threading_ != nullptr) {
    dThreadingFreeImplementation(threading_);
  }
}

}  // namespace leglab::sim
