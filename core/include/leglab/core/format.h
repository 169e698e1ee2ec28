#pragma once

#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

namespace leglab {

/// How FormatNumber writes a number.
enum class NumberStyle {
  /// The shortest text that reads back as the same double ("0.1", "1e+06", "-7.5e-05"): what
  /// the result files hold, so that a value read back is bit for bit the one computed.
  kShortest,
  /// For people (messages, the configuration reference): a whole number below 10^15 written
  /// out ("1000000"), anything else with kShortest's digits in printf's %g notation ("0.0001",
  /// not kShortest's "1e-04"; "1e-06").
  kReadable,
};

/// Appends FormatNumber(value) (kShortest) to `out`, with no temporary string: for writers
/// of many numbers (a run's trace).
inline void AppendNumber(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

/// `value` as text in `style`; "nan", "inf" and "-inf" for the non-finite values.
inline std::string FormatNumber(double value, NumberStyle style = NumberStyle::kShortest) {
  if (style == NumberStyle::kReadable && value == std::round(value) && std::abs(value) < 1e15) {
    return std::to_string(static_cast<long long>(value));
  }
  if (style == NumberStyle::kReadable) {  // %g's choice of notation: 0.0001, not 1e-04
    char buffer[32];
    const auto result =
        std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general);
    return {buffer, result.ptr};
  }
  std::string text;
  AppendNumber(text, value);
  return text;
}

/// `value` to `significant_digits` significant digits (printf's %g without trailing zeros),
/// e.g. a lattice point min + k * step written as the user wrote min and step: 0.1 + 2 * 0.1
/// to 15 digits is "0.3", not 0.30000000000000004.
inline std::string FormatNumber(double value, int significant_digits) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value,
                                    std::chars_format::general, significant_digits);
  return {buffer, result.ptr};
}

/// `value` with `decimals` digits after the point (printf's %.*f), as long as it needs: %.2f of
/// 1e300 is 303 characters. For the tables people read ("2.50").
inline std::string FormatFixed(double value, int decimals) {
  const int size = std::snprintf(nullptr, 0, "%.*f", decimals, value);
  std::string text(static_cast<size_t>(size) + 1, '\0');
  std::snprintf(text.data(), text.size(), "%.*f", decimals, value);
  text.resize(static_cast<size_t>(size));
  return text;
}

}  // namespace leglab
