#pragma once

// Conversions between Python values and leglab's C++ types, shared by the binding files. Every
// check raises one line naming the item (what the programs print for bad input): TypeError for
// a value of the wrong type, ValueError for a wrong value; never crashes the interpreter.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/core/config_keys.h"
#include "leglab/core/leg.h"
#include "leglab/model/kinematics.h"

namespace leglab::python {

namespace py = pybind11;

/// A C-contiguous float64 array.
using DoubleArray = py::array_t<double, py::array::c_style>;

/// Raises ValueError with `message` as one line (MessageLine: control characters escaped, long
/// text cut), as the programs print bad input.
[[noreturn]] void ThrowValueError(std::string_view message);

/// Raises TypeError with `message` as one line, for a value of the wrong type (Python's own
/// convention: a str where a number goes), where ValueError is for a wrong value.
[[noreturn]] void ThrowTypeError(std::string_view message);

/// `value` as a real number: a Python int or float, or a numpy integer or floating scalar.
/// bool is not taken as a number. TypeError "<what>: expected a number, got <type>" for another
/// type; ValueError for an int too large for a double and, with `finite`, for NaN or infinity.
double ToReal(py::handle value, std::string_view what, bool finite = true);

/// None as nullopt, anything else as ToReal (finite).
std::optional<double> ToOptionalReal(py::handle value, std::string_view what);

/// Adds each of `values` (KeyValues: a struct's numeric keys) to `dict` under its key's name,
/// an integer key as an int.
void AddKeyValues(py::dict& dict, const std::vector<KeyValue>& values);

/// `value` as an integer in the range `doc` declares: a Python int or a numpy integer (not a
/// bool, not a float, even a whole one). TypeError for another type; ValueError "<what> must
/// be an integer in [min, max], got N" outside the range, before anything is allocated for it.
long long ToInteger(py::handle value, std::string_view what, const KeyDoc& doc);

/// The most values an array argument may hold (800 MB as float64, 3 days of a leg's 8 ms
/// ticks): a larger one (a broadcast view of 10^9 rows costs nothing to make) is refused before
/// its copy is made.
inline constexpr py::ssize_t kMaxArrayValues = 100'000'000;

/// `value` as a float64 array (numpy.asarray, then converted): integers and floats are taken.
/// No array at all (None, a str or bytes, a dict or set, an object numpy holds as one item)
/// raises TypeError "<what>: expected an array of numbers, got <type>"; an array or sequence of
/// anything else (bool, complex, text, objects, ragged lists) ValueError "<what>: ...", as does
/// one of more than kMaxArrayValues values. MemoryError naming it when its copy cannot be made.
DoubleArray RealArray(py::handle value, std::string_view what);

/// `value` as one angle per joint (shape (3,), rotator, abductor, knee). With `finite`, a NaN or
/// infinite angle raises ValueError naming the joint.
LegAngles ToLegAngles(py::handle value, std::string_view what, bool finite = true);

/// `value` as rows of joint angles, shape (T, 3), every angle finite; ValueError naming the
/// first bad row and joint otherwise.
std::vector<LegAngles> ToAngleRows(py::handle value, std::string_view what);

/// `value` as a 1-D array of finite numbers (at least `min_size` of them).
std::vector<double> ToFiniteVector(py::handle value, std::string_view what, size_t min_size = 0);

/// Arrays for Python: (3,), (N,) and (N, 3), float64, copies.
DoubleArray ToArray(const LegAngles& angles);
DoubleArray ToArray(const std::vector<double>& values);
DoubleArray ToArray(const std::vector<LegAngles>& rows);

/// Each joint's (lower, upper) limit, deg, shape (3, 2).
DoubleArray ToLimitsArray(const std::array<JointLimits, kLegJoints>& limits);

/// A file path from a str or an os.PathLike; TypeError naming `what` for anything else.
std::string ToPath(py::handle path, std::string_view what);

/// A dict {key: value} of config keys as the programs' `--set key=value` strings, in the dict's
/// order. A str value is written as it is (YAML text, e.g. "sim" or "[direct, optimal]");
/// numbers, booleans, lists and dicts as JSON, which YAML reads as the same values. None gives
/// no overrides. TypeError for what is not a dict, a key that is not a str and a value JSON
/// cannot write (an object); ValueError for a NaN or infinite value.
std::vector<std::string> ToOverrides(py::handle overrides);

}  // namespace leglab::python
