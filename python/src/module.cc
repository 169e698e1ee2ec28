// leglab._leglab: the compiled part of the leglab Python package (see python/README.md). Bad
// input raises ValueError with the programs' one-line message (a value of the wrong type,
// TypeError); a failure to write, OSError.
#include <pybind11/pybind11.h>

#include <exception>
#include <stdexcept>

#include "bindings.h"
#include "leglab/app/output.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/program.h"

namespace py = pybind11;

namespace {

// What the programs report as bad input (exit 2) is the caller's: ValueError, one line; a
// failure to write, OSError. The parameter is by value: pybind11's translator signature.
void TranslateException(std::exception_ptr p) {  // NOLINT(performance-unnecessary-value-param)
  using leglab::MessageLine;
  try {
    if (p) std::rethrow_exception(p);
  } catch (const leglab::OutputError& e) {
    PyErr_SetString(PyExc_OSError, MessageLine(e.what()).c_str());
  } catch (const leglab::InputError& e) {
    PyErr_SetString(PyExc_ValueError, MessageLine(e.what()).c_str());
  } catch (const std::invalid_argument& e) {
    PyErr_SetString(PyExc_ValueError, MessageLine(e.what()).c_str());
  } catch (const std::domain_error& e) {
    PyErr_SetString(PyExc_ValueError, MessageLine(e.what()).c_str());
  }
}

}  // namespace

PYBIND11_MODULE(_leglab, m) {
  m.doc() =
      "leglab's C++ core: plants, joint models, Table 2's experiment and real servos (see "
      "leglab, leglab.servo).";
  // Each docstring starts with its Python signature, written for people (pybind11's would name
  // the C++ types it converts through).
  py::options options;
  options.disable_function_signatures();

  py::register_exception_translator(&TranslateException);

  leglab::python::BindModel(m);
  leglab::python::BindPlant(m);
  leglab::python::BindTrack(m);
  leglab::python::BindServo(m);
}
