#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
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

// What a PCD header promises, to hold against the file before any reader allocates.
struct PcdLayout {
  std::vector<std::uint64_t> sizes, counts;
  std::uint64_t width = 0, height = 1, points = 0;
  bool has_width = false, has_points = false;
  std::string data;
  std::uint64_t header_bytes = 0;  // bytes up to and including the DATA line

  // Bytes of one point, or nothing when the sum does not fit 64 bits.
  std::optional<std::uint64_t> pointBytes() const {
    std::uint64_t total = 0;
    for (std::size_t i = 0; i < sizes.size(); ++i) {
      if (counts[i] != 0 && sizes[i] > UINT64_MAX / counts[i])
        return std::nullopt;
      const std::uint64_t field = sizes[i] * counts[i];
      if (total > UINT64_MAX - field)
        return std::nullopt;
      total += field;
    }
    return total;
  }
};

// The least a binary_compressed file can compress to: LZF (PCL's codec) writes at least
// 3 bytes for every 264 bytes of a run.
constexpr std::uint64_t MAX_LZF_RATIO = 88;

std::vector<std::uint64_t> countsOf(const std::string& path, const std::vector<std::string>& t) {
  std::vector<std::uint64_t> out;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (!isCount(t[i]))
      malformed(path, "PCD " + t[0] + " holds '" + t[i] + "', not a count");
    out.push_back(std::stoull(t[i]));
  }
  return out;
}

void readPcdHeaderLine(const std::string& path, const std::string& line, PcdLayout& h,
                       std::size_t& fields) {
  const auto t = tokens(line);
  if (t.empty() || t[0][0] == '#')
    return;
  const std::string& key = t[0];
  if (key == "VERSION" || key == "VIEWPOINT")
    return;
  if (key == "FIELDS") {
    fields = t.size() - 1;
  } else if (key == "SIZE" || key == "TYPE" || key == "COUNT") {
    if (fields == 0 || t.size() - 1 != fields)
      malformed(path, "PCD " + key + " does not match FIELDS");
    if (key == "SIZE")
      h.sizes = countsOf(path, t);
    if (key == "COUNT")
      h.counts = countsOf(path, t);
  } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
    if (t.size() != 2 || !isCount(t[1]))
      malformed(path, "PCD " + key + " is not a count");
    const std::uint64_t v = std::stoull(t[1]);
    (key == "WIDTH" ? h.width : key == "HEIGHT" ? h.height : h.points) = v;
    h.has_width = h.has_width || key == "WIDTH";
    h.has_points = h.has_points || key == "POINTS";
  } else if (key == "DATA") {
    if (t.size() != 2 || (t[1] != "ascii" && t[1] != "binary" && t[1] != "binary_compressed"))
      malformed(path, "PCD DATA must be ascii, binary or binary_compressed");
    if (fields == 0 || !h.has_width || !h.has_points)
      malformed(path, "PCD header lacks FIELDS, WIDTH or POINTS");
    h.data = t[1];
  } else {
    malformed(path, "not a PCD file (unexpected header line '" + line.substr(0, 40) + "')");
  }
}

// The points the header promises must fit in the bytes the file has: a 178-byte file must
// not make a reader allocate gigabytes.
void checkPcdAgainstFile(const std::string& path, std::ifstream& in, PcdLayout& h,
                         std::uint64_t file_bytes) {
  if (h.counts.empty())
    h.counts.assign(h.sizes.size(), 1);  // COUNT is optional: one value per field
  if (h.sizes.empty() || h.sizes.size() != h.counts.size())
    malformed(path, "PCD header lacks SIZE");
  if (h.height == 0 || h.points % h.height != 0 || h.points / h.height != h.width)
    malformed(path, "PCD WIDTH x HEIGHT is not POINTS");
  const auto point_bytes = h.pointBytes();
  const std::uint64_t body = file_bytes - h.header_bytes;
  const auto too_large = [&](std::uint64_t need) {
    malformed(path, "the header promises " + std::to_string(h.points) + " points (" +
                        std::to_string(need) + " bytes) but the file holds " +
                        std::to_string(body) + " bytes of data");
  };
  if (!point_bytes || (*point_bytes != 0 && h.points > UINT64_MAX / *point_bytes))
    too_large(UINT64_MAX);
  const std::uint64_t need = h.points * *point_bytes;
  if (h.data == "binary" && need > body)
    too_large(need);
  // ASCII: at least one character and a separator per value.
  std::uint64_t values = 0;
  for (const auto c : h.counts)
    values += c;
  if (h.data == "ascii" && h.points > 0 && values > body / h.points / 2 + 1)
    too_large(need);
  if (h.data == "binary_compressed") {
    std::uint32_t sizes[2] = {0, 0};
    in.read(reinterpret_cast<char*>(sizes), sizeof sizes);
    if (!in)
      malformed(path, "binary_compressed PCD without its size fields");
    if (sizes[1] != need)
      malformed(path, "binary_compressed PCD: " + std::to_string(sizes[1]) +
                          " uncompressed bytes declared, the header's points need " +
                          std::to_string(need));
    if (sizes[0] > body - sizeof sizes || sizes[1] > MAX_LZF_RATIO * sizes[0] + 1024)
      too_large(need);
  }
}

// PCL 1.13's readers dereference header fields they never validated (a text file that is not
// a PCD crashes PCDReader::read), so the header is checked here before PCL sees the file.
void checkPcdHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw Error(ErrorCode::FILE_NOT_FOUND, "cannot open " + path);
  in.seekg(0, std::ios::end);
  const auto file_bytes = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  PcdLayout h;
  std::size_t fields = 0;
  std::string line;
  for (int n = 0; n < 64 && std::getline(in, line); ++n) {
    readPcdHeaderLine(path, line, h, fields);
    if (!h.data.empty()) {
      h.header_bytes = static_cast<std::uint64_t>(in.tellg());
      checkPcdAgainstFile(path, in, h, file_bytes);
      return;
    }
  }
  malformed(path, "not a PCD file (no DATA line in the header)");
}

void checkPlyHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw Error(ErrorCode::FILE_NOT_FOUND, "cannot open " + path);
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

RawPoints readPclFile(const std::string& path, bool is_ply, bool* single_precision) {
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
  if (single_precision) {
    *single_precision = fx->datatype == pcl::PCLPointField::FLOAT32 ||
                        fy->datatype == pcl::PCLPointField::FLOAT32 ||
                        fz->datatype == pcl::PCLPointField::FLOAT32;
  }
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
