#pragma once

#include <stdexcept>
#include <string>

namespace panmap {

/// Bad input or a failed operation, with a one-line message naming the culprit (file, field).
class Error : public std::runtime_error {
 public:
  /// @param message one line, no trailing newline; names the file or field at fault.
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace panmap
