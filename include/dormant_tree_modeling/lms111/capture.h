#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "dormant_tree_modeling/lms111/cola.h"

namespace dormant_tree_modeling {
namespace lms111 {

/// @brief One telegram cut from recorded bytes, or what kept a frame from being one.
struct CapturedTelegram {
  std::size_t offset = 0;  ///< byte offset of the frame's first byte in the recording
  double time_s = -1.0;    ///< capture time (session files), -1 when the recording has none
  std::string payload;     ///< the telegram without framing; empty when `error` is set
  std::string error;       ///< "bad checksum", "cut-off frame", ...; empty for a good telegram
  /// Failed frames this entry stands for: findings with no good telegram between them are
  /// folded into the first (a flood of magic bytes is one entry, not one per byte).
  std::size_t failures = 1;
  std::size_t last_offset = 0;  ///< offset of the last folded failure
};

/// @brief The bytes of a recording.
/// @param what what the file is, for the message ("telegram file")
/// @throws Error FILE_NOT_FOUND for a missing path, a directory or a file that cannot be read
std::string readRecording(const std::string& path, const std::string& what);

/// @brief Cuts a recorded CoLa-B byte stream into frames. Unlike the driver's framer it keeps
/// every finding: a frame with a bad checksum or one cut off by the end of the recording is
/// reported with its offset, and cutting goes on at the next magic. Bytes between frames are
/// skipped. Linear in the input.
std::vector<CapturedTelegram> cutColaBStream(const std::string& bytes);

/// @brief Cuts a recorded CoLa-A byte stream (STX ... ETX) likewise: an STX whose telegram
/// is cut short by the next STX or by the end is reported with its offset.
std::vector<CapturedTelegram> cutColaAStream(const std::string& bytes);

/// @brief Reads a session capture: lines `<seconds> <hex bytes>`, one TCP payload a line
/// (CoLa-B frames, a frame possibly spanning lines), `#` comments and blank lines skipped.
/// @throws Error PARSE_ERROR naming the line for a line that is not of that form
std::vector<CapturedTelegram> readSessionText(const std::string& text);

/// @brief Whether the text looks like a session capture (its first data line is `<seconds> <hex>`).
bool isSessionText(const std::string& text);

/// @brief A request type (sRN, sWN, sMN, sEN): what a host sends.
bool isRequestType(const std::string& type);

/// @brief The command type and name of a payload ("sSN", "LMDscandata"); empty strings when
/// the payload does not start with two words.
std::pair<std::string, std::string> commandWords(const std::string& payload);

/// @brief The telegram text in saved data: with framing the first complete telegram, without
/// it the text itself with line ends trimmed. @throws Error PARSE_ERROR for an STX without ETX
std::string telegramText(const std::string& data);

/// @brief telegramText() of a file's content. @throws Error FILE_NOT_FOUND, PARSE_ERROR
std::string readTelegramFile(const std::string& path);

/// @brief readSessionText() of a file. @throws Error FILE_NOT_FOUND, PARSE_ERROR
std::vector<CapturedTelegram> readSessionFile(const std::string& path);

}  // namespace lms111
}  // namespace dormant_tree_modeling
