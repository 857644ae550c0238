#pragma once

#include <memory>
#include <string>
#include <vector>

#include "dormant_tree_modeling/emulation/lms111_emulator.h"
#include "dormant_tree_modeling/lms111/capture.h"

namespace dormant_tree_modeling {
namespace emulation {

/// @brief A recorded real CoLa-B session taken apart for replay: each host request with the
/// device's reply, the events, and the scans.
struct RecordedSessionParts {
  RecordedReplies replies;
  std::vector<lms111::ScanTelegram> scans;  ///< the recorded `sSN LMDscandata` telegrams, decoded
  std::size_t requests = 0;                 ///< host requests in the recording
};

/// @brief Takes a session apart (readSessionText's telegrams).
/// @throws Error PARSE_ERROR when the session holds no scan, or a recorded scan does not decode
RecordedSessionParts splitRecordedSession(const std::vector<lms111::CapturedTelegram>& session);

/// @brief A test device that replays a real session: an EmulatedLms111 (strict about every
/// request's layout, streaming at the configured frequency with advancing counters and clock)
/// that answers CoLa-B requests identical to recorded ones with the recorded replies, refuses a
/// recorded command whose size differs from the recorded request, interleaves the recorded
/// events, and streams the recorded scans (resampled to the configured beams) with the
/// recorded serial number and clock start.
/// @param config identity and timing; its serial number and clock start are the recording's
/// @throws Error as splitRecordedSession
std::shared_ptr<EmulatedLms111> makeSessionReplay(
    const std::vector<lms111::CapturedTelegram>& session, LmsEmulatorConfig config = {},
    LmsFaults faults = {});

}  // namespace emulation
}  // namespace dormant_tree_modeling
