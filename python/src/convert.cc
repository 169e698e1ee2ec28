#include "convert.h"

#include <cmath>
#include <string>

#include "leglab/app/program.h"
#include "leglab/core/units.h"

namespace leglab::python {

void ThrowValueError(std::string_view message) { throw py::value_error(MessageLine(message)); }

void ThrowTypeError(std::string_view message) { throw py::type_error(MessageLine(message)); }

namespace {

std::string TypeName(py::handle value) {
  return std::string(py::str(py::type::of(value).attr("__name__")));
}

bool IsNumpyScalar(py::handle value, const char* kind) {
  return py::isinstance(value, py::module_::import("numpy").attr(kind));
}

std::string ShapeText(const py::array& array) {
  std::string text = "(";
  for (py::ssize_t i = 0; i < array.ndim(); ++i) {
    text += std::to_string(array.shape(i));
    if (array.ndim() == 1 || i + 1 < array.ndim()) text += ",";
    if (i + 1 < array.ndim()) text += " ";
  }
  return text + ")";
}

}  // namespace

DoubleArray RealArray(py::handle value, std::string_view what) {
  // Fast path: already what we need (Plant.tick's per-call cost).
  if (DoubleArray::check_(value) &&
      py::reinterpret_borrow<py::array>(value).size() <= kMaxArrayValues) {
    return py::reinterpret_borrow<DoubleArray>(value);
  }
  // Not an array at all (None, text, a dict or set, an object numpy holds as one item): the
  // argument's type is wrong, TypeError; a sequence or array of the wrong numbers, ValueError.
  if (value.is_none() || py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value) ||
      py::isinstance<py::dict>(value) || py::isinstance<py::set>(value)) {
    ThrowTypeError(std::string(what) + ": expected an array of numbers, got " + TypeName(value));
  }
  py::array array;
  try {
    array = py::module_::import("numpy").attr("asarray")(value);
  } catch (const py::error_already_set& e) {
    // A ragged list and the like: numpy's own message says what is wrong.
    ThrowValueError(std::string(what) + ": not an array of numbers (" + e.what() + ")");
  }
  // Before any copy: a broadcast view of 10^9 rows costs nothing to make.
  if (array.size() > kMaxArrayValues) {
    ThrowValueError(std::string(what) + ": " + std::to_string(array.size()) +
                    " values, over the limit of " + std::to_string(kMaxArrayValues));
  }
  const char kind = array.dtype().kind();
  if (kind == 'O' && array.ndim() == 0 && !py::isinstance<py::array>(value)) {
    ThrowTypeError(std::string(what) + ": expected an array of numbers, got " + TypeName(value));
  }
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    ThrowValueError(std::string(what) + ": expected real numbers, got dtype " +
                    std::string(py::str(array.dtype())));
  }
  // ensure() returns a null array (and clears Python's error) when the float64 copy cannot be
  // made, which for real numbers means memory: MemoryError naming the item, never a null array.
  DoubleArray copy = DoubleArray::ensure(array);
  if (!copy) {
    PyErr_SetString(PyExc_MemoryError,
                    MessageLine(std::string(what) + ": no memory for a float64 copy of " +
                                std::to_string(array.size()) + " values")
                        .c_str());
    throw py::error_already_set();
  }
  return copy;
}

double ToReal(py::handle value, std::string_view what, bool finite) {
  double number = 0.0;
  if (PyFloat_CheckExact(value.ptr())) {  // the common case first: a per-tick call's cost
    number = PyFloat_AS_DOUBLE(value.ptr());
  } else if (PyBool_Check(value.ptr()) || IsNumpyScalar(value, "bool_")) {
    ThrowTypeError(std::string(what) + ": expected a number, got bool");
  } else if (PyFloat_Check(value.ptr())) {
    number = PyFloat_AsDouble(value.ptr());
  } else if (PyLong_Check(value.ptr())) {
    number = PyLong_AsDouble(value.ptr());
    if (number == -1.0 && PyErr_Occurred() != nullptr) {
      PyErr_Clear();
      ThrowValueError(std::string(what) + ": " + std::string(py::str(value)).substr(0, 30) +
                      "... is too large for a number");
    }
  } else if (IsNumpyScalar(value, "integer") || IsNumpyScalar(value, "floating")) {
    number = py::float_(py::reinterpret_borrow<py::object>(value)).cast<double>();
  } else {
    ThrowTypeError(std::string(what) + ": expected a number, got " + TypeName(value));
  }
  if (finite && !std::isfinite(number)) {
    ThrowValueError(std::string(what) + ": expected a finite number, got " +
                    std::string(py::str(py::float_(number))));
  }
  return number;
}

std::optional<double> ToOptionalReal(py::handle value, std::string_view what) {
  if (value.is_none()) return std::nullopt;
  return ToReal(value, what);
}

void AddKeyValues(py::dict& dict, const std::vector<KeyValue>& values) {
  for (const KeyValue& k : values) {
    dict[py::str(k.key)] = k.integer ? py::object(py::int_(static_cast<long long>(k.value)))
                                     : py::object(py::float_(k.value));
  }
}

long long ToInteger(py::handle value, std::string_view what, const KeyDoc& doc) {
  const std::string name(what);
  if (PyBool_Check(value.ptr()) || IsNumpyScalar(value, "bool_")) {
    ThrowTypeError(name + ": expected an integer, got bool");
  }
  py::object integer;
  if (PyLong_Check(value.ptr())) {
    integer = py::reinterpret_borrow<py::object>(value);
  } else if (IsNumpyScalar(value, "integer")) {
    integer = py::int_(py::reinterpret_borrow<py::object>(value));
  } else {
    ThrowTypeError(name + ": expected an integer, got " + TypeName(value) +
                   (PyFloat_Check(value.ptr()) ? " " + std::string(py::repr(value)) : ""));
  }
  int overflow = 0;
  const long long number = PyLong_AsLongLongAndOverflow(integer.ptr(), &overflow);
  const std::string problem =
      overflow != 0 ? "in " + RangeText(doc) : KeyValueProblem(static_cast<double>(number), doc);
  if (!problem.empty()) {
    std::string text = std::string(py::str(integer));
    if (text.size() > 30) text = text.substr(0, 30) + "...";
    ThrowValueError(name + " must be an integer " + problem + ", got " + text);
  }
  return number;
}

LegAngles ToLegAngles(py::handle value, std::string_view what, bool finite) {
  // Fast path: a list or tuple of three Python floats (Plant.tick's per-call cost); anything
  // else goes through numpy and its checks.
  if ((PyList_CheckExact(value.ptr()) || PyTuple_CheckExact(value.ptr())) &&
      PySequence_Fast_GET_SIZE(value.ptr()) == kLegJoints) {
    PyObject** items = PySequence_Fast_ITEMS(value.ptr());
    if (PyFloat_CheckExact(items[0]) && PyFloat_CheckExact(items[1]) &&
        PyFloat_CheckExact(items[2])) {
      LegAngles angles{};
      for (int j = 0; j < kLegJoints; ++j) angles[j] = PyFloat_AS_DOUBLE(items[j]);
      bool all_finite = true;
      for (const double a : angles) all_finite = all_finite && std::isfinite(a);
      if (all_finite || !finite) return angles;
    }
  }
  const DoubleArray array = RealArray(value, what);
  if (array.ndim() != 1 || array.shape(0) != kLegJoints) {
    ThrowValueError(std::string(what) +
                    ": expected 3 angles (rotator, abductor, knee), deg, got shape " +
                    ShapeText(array));
  }
  LegAngles angles{};
  const double* data = array.data();
  for (int j = 0; j < kLegJoints; ++j) {
    angles[j] = data[j];
    if (finite && !std::isfinite(angles[j])) {
      ThrowValueError(std::string(what) + ": the " + std::string(kLegJointNames[j]) +
                      "'s angle is " + std::string(py::str(py::float_(angles[j]))));
    }
  }
  return angles;
}

std::vector<LegAngles> ToAngleRows(py::handle value, std::string_view what) {
  const DoubleArray array = RealArray(value, what);
  if (array.ndim() != 2 || array.shape(1) != kLegJoints) {
    ThrowValueError(std::string(what) +
                    ": expected shape (T, 3), one row of rotator, abductor, knee angles (deg) a "
                    "tick, got shape " +
                    ShapeText(array));
  }
  const auto rows = static_cast<size_t>(array.shape(0));
  std::vector<LegAngles> angles(rows);
  const double* data = array.data();
  for (size_t t = 0; t < rows; ++t) {
    for (int j = 0; j < kLegJoints; ++j) {
      angles[t][j] = data[t * kLegJoints + j];
      if (!std::isfinite(angles[t][j])) {
        ThrowValueError(std::string(what) + "[" + std::to_string(t) + ", " + std::to_string(j) +
                        "] (the " + std::string(kLegJointNames[j]) + ") is " +
                        std::string(py::str(py::float_(angles[t][j]))));
      }
    }
  }
  return angles;
}

std::vector<double> ToFiniteVector(py::handle value, std::string_view what, size_t min_size) {
  const DoubleArray array = RealArray(value, what);
  if (array.ndim() != 1) {
    ThrowValueError(std::string(what) + ": expected a 1-D array, got shape " + ShapeText(array));
  }
  std::vector<double> values(array.data(), array.data() + array.shape(0));
  if (values.size() < min_size) {
    ThrowValueError(std::string(what) + ": expected at least " + std::to_string(min_size) +
                    " values, got " + std::to_string(values.size()));
  }
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      ThrowValueError(std::string(what) + "[" + std::to_string(i) + "] is " +
                      std::string(py::str(py::float_(values[i]))));
    }
  }
  return values;
}

DoubleArray ToArray(const LegAngles& angles) {
  DoubleArray array(kLegJoints);
  std::copy(angles.begin(), angles.end(), array.mutable_data());
  return array;
}

DoubleArray ToArray(const std::vector<double>& values) {
  DoubleArray array(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), array.mutable_data());
  return array;
}

DoubleArray ToArray(const std::vector<LegAngles>& rows) {
  DoubleArray array({static_cast<py::ssize_t>(rows.size()), py::ssize_t{kLegJoints}});
  double* data = array.mutable_data();
  for (size_t t = 0; t < rows.size(); ++t) {
    for (int j = 0; j < kLegJoints; ++j) data[t * kLegJoints + j] = rows[t][j];
  }
  return array;
}

DoubleArray ToLimitsArray(const std::array<JointLimits, kLegJoints>& limits) {
  DoubleArray array({py::ssize_t{kLegJoints}, py::ssize_t{2}});
  auto rows = array.mutable_unchecked<2>();
  for (py::ssize_t j = 0; j < kLegJoints; ++j) {
    rows(j, 0) = RadToDeg(limits[j].lower_rad);
    rows(j, 1) = RadToDeg(limits[j].upper_rad);
  }
  return array;
}

std::string ToPath(py::handle path, std::string_view what) {
  if (py::isinstance<py::str>(path)) return path.cast<std::string>();
  if (py::hasattr(path, "__fspath__")) {
    const py::object text = path.attr("__fspath__")();
    if (py::isinstance<py::str>(text)) return text.cast<std::string>();
  }
  ThrowTypeError(std::string(what) + ": expected a path (str or os.PathLike), got " +
                 std::string(py::str(py::type::of(path).attr("__name__"))));
}

std::vector<std::string> ToOverrides(py::handle overrides) {
  std::vector<std::string> result;
  if (overrides.is_none()) return result;
  if (!py::isinstance<py::dict>(overrides)) {
    ThrowTypeError("overrides: expected a dict of config keys, e.g. {\"steps\": 5}, got " +
                   std::string(py::str(py::type::of(overrides).attr("__name__"))));
  }
  const py::module_ json = py::module_::import("json");
  for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(overrides)) {
    if (!py::isinstance<py::str>(key)) {
      ThrowTypeError("overrides: a key is " + std::string(py::repr(key)) +
                     ", expected a config key (str) such as \"servo.delay_ms\"");
    }
    std::string text;
    // A numpy scalar (e.g. numpy.int64(5)) as the Python number it holds.
    const py::object plain = py::isinstance(value, py::module_::import("numpy").attr("generic"))
                                 ? value.attr("item")()
                                 : py::reinterpret_borrow<py::object>(value);
    if (py::isinstance<py::str>(plain)) {
      text = plain.cast<std::string>();
    } else {
      try {
        // allow_nan=False: NaN is no YAML number; the key's own check names it below.
        text = json.attr("dumps")(plain, py::arg("allow_nan") = false).cast<std::string>();
      } catch (const py::error_already_set& e) {
        // json's TypeError: an object no config value is (a wrong type); else NaN or infinity.
        const std::string message = "overrides: " + key.cast<std::string>() + " = " +
                                    std::string(py::repr(value)) +
                                    " is not a config value (numbers, true/false, text, lists "
                                    "and maps)";
        if (e.matches(PyExc_TypeError)) ThrowTypeError(message);
        ThrowValueError(message);
      }
    }
    result.push_back(key.cast<std::string>() + "=" + text);
  }
  return result;
}

}  // namespace leglab::python
