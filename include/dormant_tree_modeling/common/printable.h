#pragma once

#include <cstddef>
#include <string>

namespace dormant_tree_modeling {

/// @brief Bytes from a device or a file fit for a log line: printable ASCII as it is, every
/// other byte (escape sequences, line ends, binary) as `\xNN`, cut after `max_bytes` with "...".
std::string printableBytes(const std::string& bytes, std::size_t max_bytes = 120);

}  // namespace dormant_tree_modeling
