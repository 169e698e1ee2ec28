#include "bindings.h"

namespace leglab::python {

void BindTrack(pybind11::module_& /*m*/) {}

}  // namespace leglab::python
