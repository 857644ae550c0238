#include "dormant_tree_modeling/emulation/session_replay.h"

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/emulation/scan_source.h"

namespace dormant_tree_modeling {
namespace emulation {

using namespace lms111;  // the emulator speaks the protocol the real driver speaks

namespace {

// The reply to the request at `index`: the first later telegram of its reply type and name, or
// an sFA, before the host's next request.
const CapturedTelegram* replyOf(const std::vector<CapturedTelegram>& session, std::size_t index) {
  const auto [type, name] = commandWords(session[index].payload);
  for (std::size_t i = index + 1; i < session.size(); ++i) {
    const auto [t, n] = commandWords(session[i].payload);
    if (isRequestType(t))
      return nullptr;
    if (t == "sFA" || (t == replyTypeOf(type) && n == name))
      return &session[i];
  }
  return nullptr;
}

}  // namespace

RecordedSessionParts splitRecordedSession(const std::vector<CapturedTelegram>& session) {
  RecordedSessionParts parts;
  for (std::size_t i = 0; i < session.size(); ++i) {
    const CapturedTelegram& t = session[i];
    if (!t.error.empty())
      continue;
    const auto [type, name] = commandWords(t.payload);
    if (isRequestType(type)) {
      ++parts.requests;
      parts.replies.request_bytes.emplace(type + " " + name, t.payload.size());
      if (const CapturedTelegram* reply = replyOf(session, i))
        parts.replies.reply_to.emplace(t.payload, reply->payload);
    } else if (type == "sSN" && name == "LMDscandata") {
      try {
        parts.scans.push_back(parseScanTelegram(t.payload, Protocol::COLA_B));
      } catch (const Error& e) {
        throw Error(ErrorCode::PARSE_ERROR, "recorded scan at byte " + std::to_string(t.offset) +
                                                " does not decode: " + e.what());
      }
    } else if (type == "sSN") {
      parts.replies.events.push_back(t.payload);
    }
  }
  if (parts.scans.empty())
    throw Error(ErrorCode::PARSE_ERROR, "the recorded session holds no LMDscandata scan");
  return parts;
}

std::shared_ptr<EmulatedLms111> makeSessionReplay(const std::vector<CapturedTelegram>& session,
                                                  LmsEmulatorConfig config, LmsFaults faults) {
  RecordedSessionParts parts = splitRecordedSession(session);
  config.serial_number = parts.scans.front().serial_number;
  config.clock_start_us = parts.scans.front().time_since_startup_us;
  auto source = std::make_shared<RecordedScanSource>(std::move(parts.scans));
  auto device = std::make_shared<EmulatedLms111>(config, source, std::move(faults));
  device->setRecording(std::move(parts.replies));
  return device;
}

}  // namespace emulation
}  // namespace dormant_tree_modeling
