#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include "dormant_tree_modeling/common/error.h"
#include "raw_points.h"

namespace dormant_tree_modeling {
namespace io {
namespace detail {

namespace {

/// Reads one scalar of any PCL field type as a double.
double readScalar(const std::uint8_t* data, std::uint8_t datatype) {
  switch (datatype) {
#define DTM_READ_AS(PCL_TYPE, CPP_TYPE) \
  case pcl::PCLPointField::PCL_TYPE: {  \
    CPP_TYPE v;                         \
    std::memcpy(&v, data, sizeof(v));   \
    return static_cast<double>(v);      \
  }
    DTM_READ_AS(INT8, std::int8_t)
    DTM_READ_AS(UINT8, std::uint8_t)
    DTM_READ_AS(INT16, std::int16_t)
    DTM_READ_AS(UINT16, std::uint16_t)
    DTM_READ_AS(INT32, std::int32_t)
    DTM_READ_AS(UINT32, std::uint32_t)
    DTM_READ_AS(FLOAT32, float)
    DTM_READ_AS(FLOAT64, double)
#undef DTM_READ_AS
  }
  return std::numeric_limits<double>::quiet_NaN();
}

std::size_t scalarSize(std::uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::INT8:
    case pcl::PCLPointField::UINT8:
      return 1;
    case pcl::PCLPointField::INT16:
    case pcl::PCLPointField::UINT16:
      return 2;
    case pcl::PCLPointField::INT32:
    case pcl::PCLPointField::UINT32:
    case pcl::PCLPointField::FLOAT32:
      return 4;
    case pcl::PCLPointField::FLOAT64:
      return 8;
    default:
      return 0;
  }
}

std::optional<pcl::PCLPointField> findField(const pcl::PCLPointCloud2& blob,
                                            const std::string& name) {
  for (const auto& f : blob.fields) {
    if (f.name == name)
      return f;
  }
  return std::nullopt;
}

std::vector<std::string> tokens(const std::string& line) {
  std::istringstream ss(line);
  std::vector<std::string> out;
  std::string t;
  while (ss >> t)
    out.push_back(t);
  return out;
}

bool isCount(const std::string& s) {
  return !s.empty() && s.size() < 19 &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

[[noreturn]] void malformed(const std::string& path, const std::string& why) {
  throw Error(ErrorCode::PARSE_ERROR, path + ": " + why);
}

// PCL 1.13's readers dereference header fields they never validated (a text file that is not
// a PCD crashes PCDReader::read), so the header is checked here before PCL sees the file.
void checkPcdHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw Error(ErrorCode::IO_FAILURE, "cannot open " + path);
  std::size_t fields = 0;
  bool has_points = false;
  bool has_width = false;
  std::string line;
  for (int n = 0; n < 64 && std::getline(in, line); ++n) {
    const auto t = tokens(line);
    if (t.empty() || t[0][0] == '#')
      continue;
    const std::string& key = t[0];
    if (key == "VERSION" || key == "VIEWPOINT" || key == "HEIGHT")
      continue;
    if (key == "FIELDS") {
      fields = t.size() - 1;
    } else if (key == "SIZE" || key == "TYPE" || key == "COUNT") {
      if (fields == 0 || t.size() - 1 != fields)
        malformed(path, "PCD " + key + " does not match FIELDS");
    } else if (key == "WIDTH" || key == "POINTS") {
      if (t.size() != 2 || !isCount(t[1]))
        malformed(path, "PCD " + key + " is not a count");
      (key == "WIDTH" ? has_width : has_points) = true;
    } else if (key == "DATA") {
      if (t.size() != 2 || (t[1] != "ascii" && t[1] != "binary" && t[1] != "binary_compressed")) {
        malformed(path, "PCD DATA must be ascii, binary or binary_compressed");
      }
      if (fields == 0 || !has_width || !has_points) {
        malformed(path, "PCD header lacks FIELDS, WIDTH or POINTS");
      }
      return;
    } else {
      malformed(path, "not a PCD file (unexpected header line '" + line.substr(0, 40) + "')");
    }
  }
  malformed(path, "not a PCD file (no DATA line in the header)");
}

void checkPlyHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw Error(ErrorCode::IO_FAILURE, "cannot open " + path);
  std::string line;
  if (!std::getline(in, line) || tokens(line) != std::vector<std::string>{"ply"}) {
    malformed(path, "not a PLY file (first line is not 'ply')");
  }
  bool vertex = false;
  bool format = false;
  for (int n = 0; n < 256 && std::getline(in, line); ++n) {
    const auto t = tokens(line);
    if (t.empty())
      continue;
    if (t[0] == "format") {
      format = t.size() == 3 &&
               (t[1] == "ascii" || t[1] == "binary_little_endian" || t[1] == "binary_big_endian");
      if (!format)
        malformed(path, "unsupported PLY format line");
    } else if (t[0] == "element") {
      if (t.size() != 3 || !isCount(t[2]))
        malformed(path, "malformed PLY element line");
      vertex = vertex || t[1] == "vertex";
    } else if (t[0] == "end_header") {
      if (!format || !vertex)
        malformed(path, "PLY header lacks format or vertex element");
      return;
    }
  }
  malformed(path, "PLY header has no end_header");
}

// Plain binary PLY with only the vertex element: PCL's writer adds a 'camera' element that
// other tools (and PCL's own reader) warn about.
void writePly(const std::string& path, const Cloud& cloud) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f)
    throw Error(ErrorCode::IO_FAILURE, "cannot write " + path);
  f << "ply\nformat binary_little_endian 1.0\ncomment dormant_tree_modeling\nelement vertex "
    << cloud.size() << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "PLY writer assumes little endian");
  for (const auto& p : cloud.points) {
    const float xyz[3] = {p.x, p.y, p.z};
    f.write(reinterpret_cast<const char*>(xyz), sizeof(xyz));
  }
  if (!f)
    throw Error(ErrorCode::IO_FAILURE, "write error in " + path);
}

void writePcd(const std::string& path, const Cloud& cloud) {
  if (cloud.empty()) {
    // PCL refuses to write an empty PCD; an empty result is still a valid, explicit file.
    std::ofstream f(path);
    f << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\n"
         "SIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 0\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
         "POINTS 0\nDATA ascii\n";
    if (!f)
      throw Error(ErrorCode::IO_FAILURE, "cannot write " + path);
    return;
  }
  int status = -1;
  try {
    status = pcl::io::savePCDFileBinary(path, cloud);
  } catch (const std::exception& e) {
    throw Error(ErrorCode::IO_FAILURE, "cannot write " + path + ": " + e.what());
  }
  if (status < 0)
    throw Error(ErrorCode::IO_FAILURE, "cannot write " + path);
}

}  // namespace

RawPoints readPclFile(const std::string& path, bool is_ply) {
  if (is_ply) {
    checkPlyHeader(path);
  } else {
    checkPcdHeader(path);
  }
  pcl::PCLPointCloud2 blob;
  int status = -1;
  try {
    status = is_ply ? pcl::io::loadPLYFile(path, blob) : pcl::io::loadPCDFile(path, blob);
  } catch (const std::exception& e) {
    malformed(path, std::string("cannot parse: ") + e.what());
  }
  if (status < 0)
    malformed(path, std::string("cannot parse as ") + (is_ply ? "PLY" : "PCD"));
  const auto fx = findField(blob, "x");
  const auto fy = findField(blob, "y");
  const auto fz = findField(blob, "z");
  if (!fx || !fy || !fz)
    malformed(path, "no x/y/z fields");
  const std::size_t n = static_cast<std::size_t>(blob.width) * blob.height;
  for (const auto* f : {&*fx, &*fy, &*fz}) {
    const std::size_t size = scalarSize(f->datatype);
    if (size == 0 || f->offset + size > blob.point_step) {
      malformed(path, "field '" + f->name + "' has an unusable layout");
    }
  }
  if (blob.data.size() < n * blob.point_step) {
    malformed(path, "truncated data (" + std::to_string(blob.data.size()) + " bytes for " +
                        std::to_string(n) + " points)");
  }
  RawPoints points;
  points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* base = blob.data.data() + i * blob.point_step;
    points.emplace_back(readScalar(base + fx->offset, fx->datatype),
                        readScalar(base + fy->offset, fy->datatype),
                        readScalar(base + fz->offset, fz->datatype));
  }
  return points;
}

void writePclFile(const std::string& path, const Cloud& cloud, const Eigen::Vector3d& offset,
                  bool is_ply) {
  const Cloud* out = &cloud;
  Cloud shifted;
  if (!offset.isZero()) {
    shifted = cloud;
    for (auto& p : shifted.points) {
      p.x = static_cast<float>(p.x + offset.x());
      p.y = static_cast<float>(p.y + offset.y());
      p.z = static_cast<float>(p.z + offset.z());
    }
    out = &shifted;
  }
  if (is_ply) {
    writePly(path, *out);
  } else {
    writePcd(path, *out);
  }
}

}  // namespace detail
}  // namespace io
}  // namespace dormant_tree_modeling
