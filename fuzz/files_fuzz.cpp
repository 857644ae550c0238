// libFuzzer target for everything that reads files a user hands the tools, and the Ensemble's
// replies: the PCD, PLY and XYZ readers (through io::readCloud, with the header checks that
// run before PCL allocates), the model and truth JSON readers, and the Ensemble reply parser
// and line framer. Every input must end in a value or an Error, never a crash, an uncaught
// exception of another type, or an allocation past libFuzzer's RSS limit.
// Built with clang's -fsanitize=fuzzer,address,undefined by `make fuzz`.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>

#include "dormant_tree_modeling/aerotech/ascii_protocol.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/tree_json.h"

using namespace dormant_tree_modeling;

namespace {

// One scratch file per format, in a directory of this process.
std::string scratch(const char* extension) {
  static const std::string dir = [] {
    std::string d = "/tmp/dtm_files_fuzz_" + std::to_string(getpid());
    std::system(("mkdir -p " + d).c_str());
    return d;
  }();
  return dir + "/input." + extension;
}

void readAs(const std::string& bytes, const char* extension) {
  const std::string path = scratch(extension);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  try {
    io::readCloud(path);
  } catch (const Error&) {
  }
}

template <typename F>
void parseJson(F parse, const std::string& text) {
  try {
    parse(text);
  } catch (const Error&) {
  }
}

void ensembleReplies(const std::string& bytes) {
  aerotech::LineFramer framer(256);
  framer.feed(bytes);
  while (auto line = framer.next()) {
    try {
      aerotech::parseReply(*line).number();
    } catch (const Error&) {
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  for (const char* extension : {"pcd", "ply", "xyz"})
    readAs(bytes, extension);
  parseJson(io::modelFromJson, bytes);
  parseJson(io::truthFromJson, bytes);
  ensembleReplies(bytes);
  return 0;
}
