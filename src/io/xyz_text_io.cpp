#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <charconv>
#include <cstdio>
#include <fstream>
#include <memory>

#include "dormant_tree_modeling/common/error.h"
#include "raw_points.h"

namespace dormant_tree_modeling {
namespace io {
namespace detail {

namespace {

bool isSeparator(char c) {
  return c == ' ' || c == '\t' || c == ',' || c == ';' || c == '\r';
}

/// Splits off the next token; returns false at the end of the line.
bool nextToken(const char*& cursor, const char* end, const char*& token_begin,
               const char*& token_end) {
  while (cursor < end && isSeparator(*cursor))
    ++cursor;
  if (cursor == end)
    return false;
  token_begin = cursor;
  while (cursor < end && !isSeparator(*cursor))
    ++cursor;
  token_end = cursor;
  return true;
}

bool parseDouble(const char* begin, const char* end, double& value) {
  if (begin < end && *begin == '+')
    ++begin;  // from_chars rejects a leading '+'
  const auto [ptr, ec] = std::from_chars(begin, end, value);
  return ec == std::errc() && ptr == end;
}

}  // namespace

RawPoints readXyzText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw Error(ErrorCode::IO_FAILURE, "cannot open " + path);
  RawPoints points;
  std::string line;
  std::size_t line_number = 0;
  bool seen_data_or_header = false;
  while (std::getline(in, line)) {
    ++line_number;
    const char* cursor = line.data();
    const char* end = line.data() + line.size();
    const char* tb = nullptr;
    const char* te = nullptr;
    if (!nextToken(cursor, end, tb, te))
      continue;  // blank line
    if (*tb == '#' || (te - tb >= 2 && tb[0] == '/' && tb[1] == '/'))
      continue;
    Eigen::Vector3d p;
    int parsed = 0;
    bool ok = true;
    do {
      if (!parseDouble(tb, te, p[parsed])) {
        ok = false;
        break;
      }
      ++parsed;
    } while (parsed < 3 && nextToken(cursor, end, tb, te));
    if (ok && parsed == 3) {
      points.push_back(p);
      seen_data_or_header = true;
      continue;
    }
    const bool header_like = !seen_data_or_header && ((*tb >= 'A' && *tb <= 'Z') ||
                                                      (*tb >= 'a' && *tb <= 'z') || *tb == '/');
    if (header_like && parsed == 0) {
      seen_data_or_header = true;  // one line of column names, e.g. "x y z intensity"
      continue;
    }
    throw Error(ErrorCode::PARSE_ERROR,
                path + ":" + std::to_string(line_number) + ": expected 'x y z', got '" +
                    line.substr(0, 80) + "'" +
                    (ok ? " (fewer than 3 columns)"
                        : " (column " + std::to_string(parsed + 1) + " is not a number)"));
  }
  if (in.bad())
    throw Error(ErrorCode::IO_FAILURE, "read error in " + path);
  return points;
}

void writeXyzText(const std::string& path, const Cloud& cloud, const Eigen::Vector3d& offset) {
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "w"), &std::fclose);
  if (!file)
    throw Error(ErrorCode::IO_FAILURE, "cannot write " + path);
  for (const auto& p : cloud.points) {
    // Micrometres: finer than float32 resolution at tree scale, and exact for survey offsets.
    std::fprintf(file.get(), "%.6f %.6f %.6f\n", p.x + offset.x(), p.y + offset.y(),
                 p.z + offset.z());
  }
  if (std::ferror(file.get()))
    throw Error(ErrorCode::IO_FAILURE, "write error in " + path);
}

}  // namespace detail
}  // namespace io
}  // namespace dormant_tree_modeling
