#pragma once

// ODE's process runtime and an owned ODE world. Private to leglab::sim: no public header
// includes ODE.

#include <ode/ode.h>

#include <type_traits>

namespace leglab::sim {

static_assert(std::is_same_v<dReal, double>, "leglab::sim needs ODE built in double precision");

/// Initialises ODE once per process (closed at exit) and allocates ODE's data for the calling
/// thread on its first call there; later calls on that thread cost one flag test. Call it
/// before creating a world and on any thread that steps one. From then on an ODE error or failed
/// ODE assertion throws std::runtime_error with ODE's message ("ODE internal error 1: assertion
/// ...") out of the ODE call instead of aborting the process; the world involved must then be
/// destroyed, not stepped again.
/// Throws std::runtime_error when ODE cannot allocate the thread's data.
void EnsureOdeReady();

/// An ODE world (dWorldID) with a threading implementation of its own, destroyed with its
/// bodies and joints. Without its own implementation dWorldStep uses a process-wide default
/// that crashes when worlds are stepped on parallel threads. Call EnsureOdeReady() first.
class OdeWorld {
 public:
  /// Throws std::runtime_error when ODE cannot create the world or its threading.
  OdeWorld();
  ~OdeWorld();
  OdeWorld(const OdeWorld&) = delete;
  OdeWorld& operator=(const OdeWorld&) = delete;

  /// The world, for creating bodies and joints in it and stepping it.
  dWorldID get() const { return world_; }

  /// Says that an ODE error was thrown out of a step of this world: its step left ODE's job
  /// list and memory arena in use, and freeing them would fail ODE's assertions in a
  /// destructor (std::terminate), so the destructor parks the world and its threading, unfreed,
  /// instead.
  void MarkBroken() noexcept { broken_ = true; }

 private:
  void Release() noexcept;

  bool broken_ = false;

  dThreadingImplementationID threading_;
  dWorldID world_;
};

}  // namespace leglab::sim
