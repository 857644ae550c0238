// lms111_decode: prints one LMDscandata telegram (CoLa-A text, STX/ETX optional) as JSON.
#include <iostream>
#include <iterator>
#include <string>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/lms111/scan_source.h"
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
  std::string text;
  try {
    if (path == "-")
      text = lms111::telegramText(std::string(std::istreambuf_iterator<char>(std::cin), {}));
    else
      text = lms111::readTelegramFile(path);
  } catch (const Error& e) {
    std::cerr << "lms111_decode: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return e.code() == ErrorCode::FILE_NOT_FOUND ? 3 : 4;
  }
  try {
    std::cout << lms111::scanTelegramToJson(lms111::parseScanTelegram(text));
    return 0;
  } catch (const Error& e) {
    std::cerr << "lms111_decode: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return 4;
  }
}
