#include "ode_world.h"

#include <ode/threading_impl.h>

#include <cstdarg>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace leglab::sim {
namespace {

// ODE reports through three handlers, and by default prints and then calls abort() (debug: a
// failed internal assertion, such as a body whose tiny mass makes its rotation NaN) or exit(1)
// (error). Either would kill a whole program, or a sweep's every point, and leave its staging
// folder behind. Decision: the error and debug handlers throw std::runtime_error carrying
// ODE's message. That is sound here because Debian's libode is C++ built with exceptions (it
// has .eh_frame and .gcc_except_table, and its C API functions are not noexcept), so the
// exception unwinds through ODE's frames like through any C++ library's. ODE's world may be
// left mid-step: the exception also unwinds the LegWorld that owns it, which only destroys
// it. The known triggers (tiny or huge masses and inertias) are refused before ODE sees them
// (LoadLegDescription); this is the net for the rest.
std::string OdeText(const char* kind, int number, const char* format, va_list args) {
  char text[512];
  std::vsnprintf(text, sizeof text, format, args);
  return std::string("ODE ") + kind + " " + std::to_string(number) + ": " + text;
}

void ThrowOdeError(int number, const char* format, va_list args) {
  throw std::runtime_error(OdeText("error", number, format, args));
}

void ThrowOdeDebug(int number, const char* format, va_list args) {
  throw std::runtime_error(OdeText("internal error", number, format, args));
}

// Messages are ODE's warnings (it carries on): one line on stderr instead of ODE's blank-lined
// block, so a program's one-line error report stays readable.
void PrintOdeMessage(int number, const char* format, va_list args) {
  std::cerr << "leglab::sim: " << OdeText("message", number, format, args) << '\n';
}

}  // namespace

void EnsureOdeReady() {
  struct Runtime {
    Runtime() {
      dSetErrorHandler(&ThrowOdeError);
      dSetDebugHandler(&ThrowOdeDebug);
      dSetMessageHandler(&PrintOdeMessage);
      dInitODE2(0);
    }
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
  // A few kilobytes once per failed run, which then ends: better than an abort. Parked where a
  // leak checker sees them reachable, since they are left on purpose.
  if (broken_) {
    try {
      static std::mutex parked_mutex;
      static auto* parked = new std::vector<std::pair<dWorldID, dThreadingImplementationID>>;
      const std::lock_guard lock(parked_mutex);
      parked->emplace_back(world_, threading_);
    } catch (...) {  // out of memory: the world is lost instead of parked, no worse
    }
    return;
  }
  if (world_ != nullptr) {
    dWorldSetStepThreadingImplementation(world_, nullptr, nullptr);
    dWorldDestroy(world_);  // and its bodies and joints
  }
  if (threading_ != nullptr) {
    dThreadingFreeImplementation(threading_);
  }
}

}  // namespace leglab::sim
