#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dormant_tree_modeling/common/printable.h"

namespace dormant_tree_modeling {
namespace lms111 {

/// @brief The two command languages of the device: CoLa-A (ASCII, port 2111) and CoLa-B
/// (binary, port 2112).
enum class Protocol { COLA_A, COLA_B };

/// @brief "CoLa-A" or "CoLa-B".
const char* protocolName(Protocol protocol);

/// @brief CoLa-A telegram delimiters (docs/protocols.md).
constexpr char STX = 0x02;
constexpr char ETX = 0x03;

/// @brief A CoLa-A command as sent on the wire: STX + text + ETX.
std::string frameColaA(const std::string& text);

/// @brief A CoLa-B frame: 02 02 02 02, payload length (uint32 big-endian), payload, XOR of the
/// payload bytes.
std::string frameColaB(const std::string& payload);

/// @brief The four bytes that start a CoLa-B frame, and the header they begin (magic and the
/// 32-bit payload length).
extern const std::string COLA_B_MAGIC;
constexpr std::size_t COLA_B_HEADER_BYTES = 8;

/// @brief A CoLa-B frame's checksum: the XOR of its payload bytes.
char colaBChecksum(const char* payload, std::size_t size);

/// @brief The payload length a CoLa-B header declares (the 4 bytes after the magic at `frame`).
std::uint32_t colaBDeclaredLength(const char* frame);

/// @brief A telegram framed for the protocol (frameColaA or frameColaB).
std::string frame(Protocol protocol, const std::string& payload);

/// @brief Cuts a byte stream of either protocol into telegram payloads (the common face of
/// ColaAFramer and ColaBFramer, so that a connection need not know its protocol).
class Framer {
 public:
  virtual ~Framer() = default;
  virtual void feed(const char* data, std::size_t size) = 0;
  void feed(const std::string& data) { feed(data.data(), data.size()); }
  /// @brief The next complete payload, if any.
  virtual std::optional<std::string> next() = 0;
  /// @brief Bytes skipped, telegrams dropped (over the bound or a bad checksum): resyncs.
  virtual std::size_t discarded() const = 0;
  virtual void clear() = 0;
};

/// @brief A framer for the protocol, bounding one payload to `max_payload` bytes.
std::unique_ptr<Framer> makeFramer(Protocol protocol, std::size_t max_payload = 65536);

/// @brief Cuts a CoLa-A byte stream into telegrams. Bytes before an STX are skipped (and
/// counted), a telegram may arrive in pieces or several in one read; a telegram longer than
/// the bound is dropped (counted) and the framer resynchronises on the next STX.
class ColaAFramer : public Framer {
 public:
  /// @param max_telegram bytes one telegram may take (a 1081-point scan with RSSI is ~11 kB)
  explicit ColaAFramer(std::size_t max_telegram = 65536) : max_telegram_(max_telegram) {}

  /// @brief Append received bytes.
  void feed(const char* data, std::size_t size) override;
  using Framer::feed;

  /// @brief The next complete telegram's text (without STX/ETX), if any.
  std::optional<std::string> next() override;
  std::size_t discarded() const override { return skipped_ + dropped_; }

  std::size_t skippedBytes() const { return skipped_; }      ///< garbage before an STX
  std::size_t droppedTelegrams() const { return dropped_; }  ///< over the bound
  std::size_t buffered() const { return buffer_.size() - pos_; }
  void clear() override {
    buffer_.clear();
    pos_ = 0;
  }

 private:
  std::size_t max_telegram_;
  std::string buffer_;
  std::size_t pos_ = 0;  // bytes of buffer_ already consumed
  std::size_t skipped_ = 0, dropped_ = 0;
};

/// @brief Cuts a CoLa-B byte stream into payloads: resynchronises on the 4-byte magic, checks
/// the length bound and the checksum; a frame with a bad checksum is dropped and counted.
class ColaBFramer : public Framer {
 public:
  explicit ColaBFramer(std::size_t max_payload = 65536) : max_payload_(max_payload) {}
  void feed(const char* data, std::size_t size) override;
  using Framer::feed;
  /// @brief The next payload whose checksum is right, if any.
  std::optional<std::string> next() override;
  std::size_t discarded() const override { return skipped_ + bad_checksum_ + dropped_; }
  void clear() override {
    buffer_.clear();
    pos_ = 0;
  }
  std::size_t skippedBytes() const { return skipped_; }
  std::size_t badChecksums() const { return bad_checksum_; }
  std::size_t droppedFrames() const { return dropped_; }  ///< declared length over the bound

 private:
  std::size_t max_payload_;
  std::string buffer_;
  std::size_t pos_ = 0;  // bytes of buffer_ already consumed
  std::size_t skipped_ = 0, bad_checksum_ = 0, dropped_ = 0;
};

/// @brief Parse a CoLa-A number token: hex without prefix, or decimal with a sign.
/// @returns nothing when the token is not a number of either form
std::optional<std::int64_t> parseColaNumber(const std::string& token);

/// @brief `sFA` error codes (docs/protocols.md; numbering as in SICK's SOPAS error table, which
/// the public sick_scan_xd driver lists in full).
enum SfaCode : int {
  SFA_ACCESS_DENIED = 1,
  SFA_UNKNOWN_METHOD = 2,
  SFA_UNKNOWN_VARIABLE = 3,
  SFA_LOCAL_CONDITION = 4,
  SFA_INVALID_DATA = 5,
  SFA_UNKNOWN_ERROR = 6,
  SFA_BUFFER_OVERFLOW = 7,
  SFA_BUFFER_UNDERFLOW = 8,
  SFA_UNKNOWN_TYPE = 9,
  SFA_WRITE_ACCESS_DENIED = 10,
  SFA_UNKNOWN_NAMESERVER_COMMAND = 11,
  SFA_UNKNOWN_COLA_COMMAND = 12,
  SFA_SERVER_BUSY = 13,
  SFA_FLEX_OUT_OF_BOUNDS = 14,
  SFA_UNKNOWN_EVENT = 15,
  SFA_COLA_A_VALUE_OVERFLOW = 16,
  SFA_COLA_A_INVALID_CHARACTER = 17,
};

/// @brief The error code of an `sFA` reply, nothing for any other payload. CoLa-A: "sFA" and
/// the code as a token; CoLa-B: "sFA" and the code as a 16-bit value right after it (as the
/// SOPAS driver of sick_scan_xd reads it from real devices), a space before it tolerated.
std::optional<int> sfaCode(Protocol protocol, const std::string& payload);

/// @brief An `sFA` reply in the device's layout.
std::string sfaReply(Protocol protocol, int code);

/// @brief Readable text of an `sFA` error code.
std::string describeSfaError(int code);

/// @brief The "authorised client" login of `sMN SetAccessMode` (level 3 and the password hash
/// every public LMS1xx driver sends).
constexpr int AUTHORISED_CLIENT_LEVEL = 3;
constexpr std::uint32_t AUTHORISED_CLIENT_PASSWORD = 0xF4724744;

/// @brief `STlms` state "ready for measurement".
constexpr int STATE_READY_FOR_MEASUREMENT = 7;

/// @brief The reply type of a request type: sRN -> sRA, sWN -> sWA, sMN -> sAN, sEN -> sEA;
/// anything else maps to itself.
std::string replyTypeOf(const std::string& request_type);

/// @brief Name of a device state as `STlms` reports it (0 undefined ... 7 ready).
std::string deviceStateName(int state);

}  // namespace lms111
}  // namespace dormant_tree_modeling
