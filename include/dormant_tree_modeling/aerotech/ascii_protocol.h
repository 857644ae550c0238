#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace dormant_tree_modeling {
namespace aerotech {

/// @brief First character of every Ensemble ASCII reply (docs/protocols.md).
enum class ReplyStatus : char {
  SUCCESS = '%',
  INVALID = '!',  ///< the controller did not understand the command
  FAULT = '#',    ///< the command caused or met an axis fault
  TIMEOUT = '$',  ///< the command timed out in the controller
};

/// @brief One reply line: status and the optional value after it (e.g. "%12.3450").
struct Reply {
  ReplyStatus status = ReplyStatus::SUCCESS;
  std::string value;

  bool ok() const { return status == ReplyStatus::SUCCESS; }
  /// @brief The value as a number. @throws Error PARSE_ERROR when it is not one
  double number() const;
};

/// @brief Parse a reply line (without its line end).
/// @throws Error PARSE_ERROR for an empty line or an unknown status character
Reply parseReply(const std::string& line);

/// @brief Readable meaning of a status: "success", "invalid command", ...
const char* replyStatusName(ReplyStatus status);

/// @brief Bits of AXISSTATUS (docs/protocols.md).
struct AxisStatus {
  std::uint32_t bits = 0;
  bool enabled() const { return bits & (1u << 0); }
  bool homed() const { return bits & (1u << 1); }
  bool inPosition() const { return bits & (1u << 2); }
  bool moveActive() const { return bits & (1u << 3); }
  bool homing() const { return bits & (1u << 14); }
  bool positiveLimit() const { return bits & (1u << 22); }
  bool negativeLimit() const { return bits & (1u << 23); }
  bool emergencyStop() const { return bits & (1u << 31); }
  /// @brief The set flags by name, e.g. "enabled, homed, in position".
  std::string describe() const;
};

constexpr std::uint32_t STATUS_ENABLED = 1u << 0;
constexpr std::uint32_t STATUS_HOMED = 1u << 1;
constexpr std::uint32_t STATUS_IN_POSITION = 1u << 2;
constexpr std::uint32_t STATUS_MOVE_ACTIVE = 1u << 3;
constexpr std::uint32_t STATUS_HOMING = 1u << 14;
constexpr std::uint32_t STATUS_POSITIVE_LIMIT = 1u << 22;
constexpr std::uint32_t STATUS_NEGATIVE_LIMIT = 1u << 23;
constexpr std::uint32_t STATUS_ESTOP = 1u << 31;

/// @brief PLANESTATUS bit 0: motion active in the plane.
constexpr std::uint32_t PLANE_MOTION_ACTIVE = 1u << 0;

/// @brief Bits of AXISFAULT (docs/protocols.md).
constexpr std::uint32_t FAULT_POSITION_ERROR = 1u << 0;
constexpr std::uint32_t FAULT_OVER_CURRENT = 1u << 1;
constexpr std::uint32_t FAULT_POSITIVE_HARD_LIMIT = 1u << 2;
constexpr std::uint32_t FAULT_NEGATIVE_HARD_LIMIT = 1u << 3;
constexpr std::uint32_t FAULT_POSITIVE_SOFT_LIMIT = 1u << 4;
constexpr std::uint32_t FAULT_NEGATIVE_SOFT_LIMIT = 1u << 5;
constexpr std::uint32_t FAULT_AMPLIFIER = 1u << 6;
constexpr std::uint32_t FAULT_FEEDBACK = 1u << 7;
constexpr std::uint32_t FAULT_ESTOP = 1u << 11;
constexpr std::uint32_t FAULT_ENCODER = 1u << 19;
constexpr std::uint32_t FAULT_COMMUNICATION = 1u << 20;

/// @brief The faults of an AXISFAULT word by name ("position error, over-current"); "none"
/// for 0, and unnamed bits as "fault bit N".
std::string describeFaults(std::uint32_t bits);

/// @brief Command lines (without the line end) of the commands the driver uses. Moves carry
/// their speed as one word, axis + "F" + value ("MOVEABS @1 30.000000 @1F5.000000"), the
/// form the EPICS motorAerotech driver sent to real Ensembles.
namespace command {
std::string enable(const std::string& axis);
std::string disable(const std::string& axis);
std::string home(const std::string& axis);
std::string waitModeNoWait();
std::string moveAbsolute(const std::string& axis, double position, double velocity);
std::string moveIncremental(const std::string& axis, double distance, double velocity);
std::string freerun(const std::string& axis, double velocity);
std::string abort(const std::string& axis);
std::string faultAck(const std::string& axis);
std::string acknowledgeAll();
/// @brief PFBKPROG: position feedback in program coordinates, the ones MOVEABS targets.
std::string positionFeedback(const std::string& axis);
/// @brief PLANESTATUS: bit 0 while the plane runs a motion, which AXISSTATUS alone can miss.
std::string planeStatus(int plane);
std::string velocityFeedback(const std::string& axis);
std::string axisStatus(const std::string& axis);
std::string axisFault(const std::string& axis);
}  // namespace command

/// @brief Cuts a byte stream into lines ("\n", a "\r" before it dropped); a line longer than
/// the bound is dropped and counted.
class LineFramer {
 public:
  explicit LineFramer(std::size_t max_line = 4096) : max_line_(max_line) {}
  void feed(const char* data, std::size_t size);
  void feed(const std::string& data) { feed(data.data(), data.size()); }
  std::optional<std::string> next();
  std::size_t droppedLines() const { return dropped_; }
  void clear() { buffer_.clear(); }

 private:
  std::size_t max_line_;
  std::string buffer_;
  bool discarding_ = false;  // inside an overlong line, until its end
  std::size_t dropped_ = 0;
};

}  // namespace aerotech
}  // namespace dormant_tree_modeling
