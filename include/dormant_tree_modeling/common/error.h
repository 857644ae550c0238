#pragma once

#include <stdexcept>
#include <string>

namespace dormant_tree_modeling {

/// @brief Why a core operation failed; tools map each code to a documented exit status.
enum class ErrorCode {
  FILE_NOT_FOUND,    ///< the input path does not exist or is not a regular file
  UNKNOWN_FORMAT,    ///< the file extension names no supported format
  PARSE_ERROR,       ///< the file exists but its content is malformed
  EMPTY_INPUT,       ///< no usable data (e.g. every point was NaN/Inf)
  INVALID_ARGUMENT,  ///< a parameter or value is out of its documented range
  IO_FAILURE,        ///< reading or writing failed at the operating-system level
  NO_TRUNK,          ///< the modeler could not find a trunk in the cloud
};

/// @brief Short stable name of an error code, e.g. "parse_error".
const char* errorCodeName(ErrorCode code);

/// @brief Exception thrown by the core library: a readable message plus a machine-usable code.
class Error : public std::runtime_error {
 public:
  /// @param code category of the failure
  /// @param message one-line, human-readable reason (what failed and why)
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}

  /// @brief Category of the failure.
  ErrorCode code() const { return code_; }

 private:
  ErrorCode code_;
};

}  // namespace dormant_tree_modeling
