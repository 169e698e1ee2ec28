#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace leglab {

/// Bad input from the user (config, robot, URDF, CSV, log, flag): the message names the item.
/// Programs print it on one line and exit with status 2, having written nothing.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad input of one kind: a config key that no reader asked for (a typo, or a key of another
/// program). A sweep treats it as a broken sweep file, not as one bad point.
class UnknownKeyError : public InputError {
 public:
  using InputError::InputError;
};

/// Refuses a file too large to read: throws InputError "<what> '<path>' is <size> bytes, over
/// the <limit_bytes>-byte limit" when the file at `path` is larger than `limit_bytes`. Reads
/// nothing; a file whose size cannot be found is left to its reader.
void CheckFileSize(const std::string& path, std::uintmax_t limit_bytes, const std::string& what);

}  // namespace leglab
