#include "dormant_tree_modeling/common/printable.h"

#include <cstdio>

namespace dormant_tree_modeling {

std::string printableBytes(const std::string& bytes, std::size_t max_bytes) {
  std::string out;
  for (std::size_t i = 0; i < bytes.size() && i < max_bytes; ++i) {
    const auto c = static_cast<unsigned char>(bytes[i]);
    if (c >= 0x20 && c < 0x7F && c != '\\') {
      out.push_back(static_cast<char>(c));
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      out += buf;
    }
  }
  if (bytes.size() > max_bytes)
    out += "...";
  return out;
}

}  // namespace dormant_tree_modeling
