#pragma once

// The parts of the leglab._leglab module, one function per binding file (module.cc calls them
// in order: a later part may use an earlier part's classes in its signatures).

#include <pybind11/pybind11.h>

namespace leglab::python {

/// JointModel, Identification, identify, floor (model/).
void BindModel(pybind11::module_& m);

/// Robot, Walk, Reading, Plant (the experiments' plants and robots).
void BindPlant(pybind11::module_& m);

/// ControllerContext, TrackRun, run_track (the experiments' Table 2 with Python controllers).
void BindTrack(pybind11::module_& m);

/// ServoModel, ServoPlanner and the private functions of leglab.servo (servo logs, the log
/// fit, plans).
void BindServo(pybind11::module_& m);

}  // namespace leglab::python
