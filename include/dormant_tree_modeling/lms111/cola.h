#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace dormant_tree_modeling {
namespace lms111 {

/// @brief CoLa-A telegram delimiters (docs/hardware.md).
constexpr char STX = 0x02;
constexpr char ETX = 0x03;

/// @brief A CoLa-A command as sent on the wire: STX + text + ETX.
std::string frameColaA(const std::string& text);

/// @brief A CoLa-B frame: 02 02 02 02, payload length (uint32 big-endian), payload, XOR of the
/// payload bytes.
std::string frameColaB(const std::string& payload);

/// @brief Cuts a CoLa-A byte stream into telegrams. Bytes before an STX are skipped (and
/// counted), a telegram may arrive in pieces or several in one read; a telegram longer than
/// the bound is dropped (counted) and the framer resynchronises on the next STX.
class ColaAFramer {
 public:
  /// @param max_telegram bytes one telegram may take (a 1081-point scan with RSSI is ~11 kB)
  explicit ColaAFramer(std::size_t max_telegram = 65536) : max_telegram_(max_telegram) {}

  /// @brief Append received bytes.
  void feed(const char* data, std::size_t size);
  void feed(const std::string& data) { feed(data.data(), data.size()); }

  /// @brief The next complete telegram's text (without STX/ETX), if any.
  std::optional<std::string> next();

  std::size_t skippedBytes() const { return skipped_; }      ///< garbage before an STX
  std::size_t droppedTelegrams() const { return dropped_; }  ///< over the bound
  std::size_t buffered() const { return buffer_.size(); }
  void clear() { buffer_.clear(); }

 private:
  std::size_t max_telegram_;
  std::string buffer_;
  std::size_t skipped_ = 0, dropped_ = 0;
};

/// @brief Cuts a CoLa-B byte stream into payloads: resynchronises on the 4-byte magic, checks
/// the length bound and the checksum; a frame with a bad checksum is dropped and counted.
class ColaBFramer {
 public:
  explicit ColaBFramer(std::size_t max_payload = 65536) : max_payload_(max_payload) {}
  void feed(const char* data, std::size_t size);
  void feed(const std::string& data) { feed(data.data(), data.size()); }
  /// @brief The next payload whose checksum is right, if any.
  std::optional<std::string> next();
  std::size_t skippedBytes() const { return skipped_; }
  std::size_t badChecksums() const { return bad_checksum_; }
  std::size_t droppedFrames() const { return dropped_; }  ///< declared length over the bound

 private:
  std::size_t max_payload_;
  std::string buffer_;
  std::size_t skipped_ = 0, bad_checksum_ = 0, dropped_ = 0;
};

/// @brief Reads the space-separated fields of a CoLa-A telegram in order, with the number
/// conventions of docs/hardware.md: hexadecimal without prefix, decimal with a +/- sign. Every
/// read throws Error PARSE_ERROR naming the field and its position when the text does not
/// hold what is asked for.
class ColaAReader {
 public:
  explicit ColaAReader(std::string text) : text_(std::move(text)) {}

  /// @brief The next token, as text.
  std::string token(const char* field);
  /// @brief Unsigned value of at most `bits` bits (hex, or decimal with '+').
  std::uint64_t unsignedValue(const char* field, int bits = 32);
  /// @brief Signed 32-bit value: two's-complement hex or signed decimal.
  std::int32_t signedValue(const char* field);
  /// @brief IEEE-754 single precision written as 8 hex digits.
  float floatValue(const char* field);
  /// @brief Exactly `length` characters after the separating space (a string may hold spaces).
  std::string characters(const char* field, std::size_t length);
  /// @brief Whether every field was read.
  bool atEnd() const;
  /// @brief Characters consumed so far.
  std::size_t position() const { return pos_; }

 private:
  [[noreturn]] void fail(const char* field, const std::string& what) const;
  std::string text_;
  std::size_t pos_ = 0;
};

/// @brief Parse a CoLa-A number token: hex without prefix, or decimal with a sign.
/// @returns nothing when the token is not a number of either form
std::optional<std::int64_t> parseColaNumber(const std::string& token);

/// @brief Readable text of an `sFA` error code (docs/hardware.md).
std::string describeSfaError(int code);

/// @brief Name of a device state as `STlms` reports it (0 undefined ... 7 ready).
std::string deviceStateName(int state);

}  // namespace lms111
}  // namespace dormant_tree_modeling
