#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {

const char* errorCodeName(ErrorCode code) {
  switch (code) {
    case ErrorCode::FILE_NOT_FOUND:
      return "file_not_found";
    case ErrorCode::UNKNOWN_FORMAT:
      return "unknown_format";
    case ErrorCode::PARSE_ERROR:
      return "parse_error";
    case ErrorCode::EMPTY_INPUT:
      return "empty_input";
    case ErrorCode::INVALID_ARGUMENT:
      return "invalid_argument";
    case ErrorCode::IO_FAILURE:
      return "io_failure";
    case ErrorCode::NO_TRUNK:
      return "no_trunk";
  }
  return "unknown";
}

}  // namespace dormant_tree_modeling
