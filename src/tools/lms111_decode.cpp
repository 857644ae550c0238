// lms111_decode: prints one LMDscandata telegram (CoLa-A text, STX/ETX optional) as JSON.
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/lms111/cola.h"
#include "dormant_tree_modeling/lms111/scan_telegram.h"

using namespace dormant_tree_modeling;

int main(int argc, char** argv) {
  if (argc != 2 || std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help") {
    std::cerr << "Usage: lms111_decode FILE\n"
                 "Decodes one LMDscandata telegram (CoLa-A text; STX/ETX optional; '-' reads "
                 "standard input) and prints it as JSON: header fields, channels with name, "
                 "scale, offset, start angle and step in degrees, count and values.\n";
    return argc == 2 ? 0 : 2;
  }
  const std::string path = argv[1];
  std::string data;
  if (path == "-") {
    data.assign(std::istreambuf_iterator<char>(std::cin), {});
  } else {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
      std::cerr << "lms111_decode: file_not_found: cannot open " << path << "\n";
      return 3;
    }
    data.assign(std::istreambuf_iterator<char>(in), {});
  }
  // With framing, the first complete telegram; without, the text itself (line ends trimmed).
  std::string text;
  if (data.find(lms111::STX) != std::string::npos) {
    lms111::ColaAFramer framer;
    framer.feed(data);
    const auto telegram = framer.next();
    if (!telegram) {
      std::cerr << "lms111_decode: parse_error: an STX without its ETX\n";
      return 4;
    }
    text = *telegram;
  } else {
    text = data;
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' '))
      text.pop_back();
  }
  try {
    std::cout << lms111::scanTelegramToJson(lms111::parseScanTelegram(text));
    return 0;
  } catch (const Error& e) {
    std::cerr << "lms111_decode: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return 4;
  }
}
