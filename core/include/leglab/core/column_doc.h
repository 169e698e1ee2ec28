#pragma once

#include <string_view>

namespace leglab {

/// One column of a table a program writes: its name as the CSV header and the Python
/// package's dict keys spell it, its unit ("" for a count, a name or a flag) and what it holds.
/// A name with `<...>` stands for several columns (one per mode, joint or swept key).
struct ColumnDoc {
  std::string_view name;
  std::string_view unit;
  std::string_view description;
};

}  // namespace leglab
