// Aerotech Ensemble ASCII: reply parsing, status and fault decoding, the emulator's kinematics
// and the client against the emulator on 127.0.0.1 (faults, dropped and idle sockets).
#include <gtest/gtest.h>

#include <boost/asio.hpp>
#include <chrono>
#include <cmath>
#include <future>
#include <list>
#include <thread>

#include "dormant_tree_modeling/aerotech/ascii_protocol.h"
#include "dormant_tree_modeling/aerotech/ensemble_client.h"
#include "dormant_tree_modeling/aerotech/stage_controller.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/emulation/ensemble_server.h"

namespace dormant_tree_modeling {
namespace aerotech {
namespace {

using namespace emulation;  // the tests run the driver against the device emulators

TEST(AerotechProtocol, RepliesStatusAndFaults) {
  const Reply q = parseReply("%12.3450");
  EXPECT_TRUE(q.ok());
  EXPECT_DOUBLE_EQ(q.number(), 12.345);
  EXPECT_EQ(parseReply("!").status, ReplyStatus::INVALID);
  EXPECT_EQ(parseReply("#").status, ReplyStatus::FAULT);
  EXPECT_EQ(parseReply("$").status, ReplyStatus::TIMEOUT);
  EXPECT_THROW(parseReply(""), Error);
  EXPECT_THROW(parseReply("ok"), Error);
  EXPECT_THROW(parseReply("%abc").number(), Error);
  EXPECT_EQ(AxisStatus{STATUS_ENABLED | STATUS_HOMED | STATUS_IN_POSITION}.describe(),
            "enabled, homed, in position");
  EXPECT_TRUE(AxisStatus{STATUS_ESTOP}.emergencyStop());
  EXPECT_EQ(describeFaults(0), "none");
  EXPECT_EQ(describeFaults(FAULT_POSITION_ERROR | FAULT_ESTOP), "position error, emergency stop");
  EXPECT_EQ(describeFaults(1u << 9), "bit 9");
  EXPECT_EQ(command::moveAbsolute("X", 10.0, 5.0), "MOVEABS X 10.000000 XF5.000000");
  EXPECT_EQ(command::positionFeedback("@1"), "PFBKPROG(@1)");
  EXPECT_EQ(command::planeStatus(0), "PLANESTATUS(0)");
}

TEST(AerotechProtocol, LineFramerSplitsCoalescesAndBounds) {
  LineFramer f(16);
  f.feed("%1.5\r\n%");
  EXPECT_EQ(*f.next(), "%1.5");
  EXPECT_FALSE(f.next());
  f.feed("2\n" + std::string(40, 'x') + "\n#\n");
  EXPECT_EQ(*f.next(), "%2");
  EXPECT_EQ(*f.next(), "#");  // the overlong line is dropped whole
  EXPECT_EQ(f.droppedLines(), 1u);
}

EmulatedAxisConfig rotary() {
  EmulatedAxisConfig c;
  c.name = "X";
  c.max_velocity = 90.0;
  c.acceleration = 180.0;
  c.home_velocity = 45.0;
  c.initial_position = 10.0;
  return c;
}

TEST(EmulatedEnsemble, TrapezoidalMovesHomingLimitsAndFaults) {
  EmulatedEnsemble e({rotary()});
  EXPECT_EQ(e.handle("MOVEABS X 20 XF10", 0.0).line, "#");  // not enabled
  EXPECT_EQ(e.handle("ENABLE X", 0.0).line, "%");
  // HOME blocks until the axis reaches 0 at 45 deg/s: 10 deg with 0.25 s ramps.
  const EnsembleResponse home = e.handle("HOME X", 0.0);
  EXPECT_EQ(home.line, "%");
  // 10 deg is too short to reach 45 deg/s at 180 deg/s^2: a triangular profile.
  EXPECT_NEAR(home.ready_at_s, 2.0 * std::sqrt(10.0 / 180.0), 1e-9);
  EXPECT_EQ(e.handle("WAIT MODE NOWAIT", 1.0).line, "%");
  // 90 deg at 90 deg/s with 180 deg/s^2: 0.5 s ramps, 1.5 s in all; half-way at 0.75 s.
  EXPECT_EQ(e.handle("MOVEABS X 90 XF90", 1.0).ready_at_s, 1.0);  // NOWAIT: replies at once
  EXPECT_NEAR(e.position("X", 1.75), 45.0, 1e-9);
  EXPECT_NEAR(e.position("X", 1.25), 0.5 * 180.0 * 0.25 * 0.25, 1e-9);
  EXPECT_EQ(e.handle("AXISSTATUS(X)", 1.5).line,
            "%" + std::to_string(STATUS_ENABLED | STATUS_HOMED | STATUS_MOVE_ACTIVE));
  EXPECT_NEAR(parseReply(e.handle("VFBK(X)", 1.75).line).number(), 90.0, 0.5);
  EXPECT_NEAR(parseReply(e.handle("PFBKPROG(X)", 3.0).line).number(), 90.0, 1e-9);
  // Past the hard limit: stops there, faulted and disabled.
  e.handle("MOVEINC X 200 XF90", 3.0);
  EXPECT_NEAR(e.position("X", 10.0), 180.0, 1e-9);
  EXPECT_EQ(e.handle("AXISFAULT(X)", 10.0).line, "%" + std::to_string(FAULT_POSITIVE_HARD_LIMIT));
  EXPECT_EQ(e.handle("ENABLE X", 10.0).line, "#");  // acknowledge first
  EXPECT_EQ(e.handle("FAULTACK X", 10.0).line, "%");
  EXPECT_EQ(e.handle("ENABLE X", 10.0).line, "%");
  EXPECT_EQ(e.handle("FLY X", 10.0).line, "!");
  EXPECT_EQ(e.handle("PFBKPROG(Z)", 10.0).line, "!");
  EXPECT_EQ(e.handle("MOVEABS X abc", 10.0).line, "!");
  EXPECT_EQ(e.handle("MOVEABS X 10 XF 5", 10.0).line, "!");   // the speed is one word
  EXPECT_EQ(e.handle("MOVEABS @0 10 @0F5", 10.0).line, "%");  // by index, as motorAerotech
}

// The client against a served emulator with a rotary axis X and a slide Y.
struct Rig {
  explicit Rig(EnsembleFaults faults = {}) {
    EmulatedAxisConfig slide;
    slide.name = "Y";
    slide.max_velocity = 100.0;  // mm/s
    slide.acceleration = 500.0;
    slide.min_limit = 0.0;
    slide.max_limit = 600.0;
    slide.home_velocity = 200.0;
    controller = std::make_shared<EmulatedEnsemble>(
        std::vector<EmulatedAxisConfig>{rotary(), slide}, faults);
    server = std::make_unique<EnsembleServer>(controller, "127.0.0.1", 0);
    EnsembleClientConfig c;
    c.host = "127.0.0.1";
    c.port = server->port();
    c.reply_timeout_s = 1.0;
    c.home_timeout_s = 5.0;
    client = std::make_unique<EnsembleClient>(c);
  }
  std::shared_ptr<EmulatedEnsemble> controller;
  std::unique_ptr<EnsembleServer> server;
  std::unique_ptr<EnsembleClient> client;
};

TEST(EnsembleClient, EnablesHomesMovesAndReadsBack) {
  Rig rig;
  rig.client->enable("X");
  rig.client->home("X");  // blocks until homed
  EXPECT_TRUE(rig.client->status("X").homed());
  EXPECT_NEAR(rig.client->position("X"), 0.0, 1e-6);
  rig.client->moveAbsolute("X", 30.0, 90.0);  // returns at once (WAIT MODE NOWAIT)
  EXPECT_TRUE(rig.client->status("X").moveActive());
  rig.client->waitForMove("X", 3.0);
  EXPECT_NEAR(rig.client->position("X"), 30.0, 1e-6);
  rig.client->moveIncremental("X", -5.0, 90.0);
  rig.client->waitForMove("X", 3.0);
  EXPECT_NEAR(rig.client->position("X"), 25.0, 1e-6);
  EXPECT_EQ(rig.client->reconnects(), 0u);
}

TEST(EnsembleClient, AMoveIsDoneOnlyWhenItsPlaneIsIdleToo) {
  // The controller's AXISSTATUS reports the move 0.2 s late; PLANESTATUS at once.
  EnsembleFaults faults;
  faults.axis_status_latency_s = 0.2;
  Rig rig(faults);
  rig.client->enable("X");
  rig.client->home("X");
  rig.client->moveAbsolute("X", 45.0, 90.0);
  EXPECT_FALSE(rig.client->status("X").moveActive()) << "inside the latency window";
  EXPECT_TRUE(rig.client->planeMoving());
  rig.client->waitForMove("X", 3.0);
  EXPECT_NEAR(rig.client->position("X"), 45.0, 1e-6) << "waited for the move, not the status";
  EXPECT_FALSE(rig.client->planeMoving());
}

TEST(EnsembleClient, AFaultMidMoveIsDecoded) {
  EnsembleFaults faults;
  faults.fault_axis = "Y";
  faults.fault_on_move = 2;  // homing is the first
  Rig rig(faults);
  rig.client->enable("Y");
  rig.client->home("Y");
  rig.client->moveAbsolute("Y", 100.0, 100.0);
  try {
    rig.client->waitForMove("Y", 3.0);
    FAIL() << "the fault went unnoticed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("axis Y faulted during the move: position error"),
              std::string::npos)
        << e.what();
  }
  try {
    rig.client->moveAbsolute("Y", 50.0, 100.0);  // faulted axes are disabled
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("axis fault (position error)"), std::string::npos)
        << e.what();
  }
  rig.client->faultAck("Y");
  rig.client->enable("Y");
  rig.client->moveAbsolute("Y", 50.0, 100.0);
  rig.client->waitForMove("Y", 3.0);
  EXPECT_NEAR(rig.client->position("Y"), 50.0, 1e-6);
}

TEST(EnsembleClient, ReconnectsAfterDroppedAndIdleSocketsAndReportsInvalidCommands) {
  EnsembleFaults faults;
  faults.drop_after_commands = 5;
  faults.idle_timeout_s = 0.3;
  faults.invalid_commands = {"FREERUN"};
  Rig rig(faults);
  for (int i = 0; i < 8; ++i)  // the socket drops after the 5th reply: the 6th reconnects
    EXPECT_NEAR(rig.client->position("X"), 10.0, 1e-6);
  EXPECT_EQ(rig.client->reconnects(), 1u);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // idle: the controller closes
  EXPECT_NEAR(rig.client->position("Y"), 0.0, 1e-6);
  EXPECT_EQ(rig.client->reconnects(), 2u);
  try {
    rig.client->freerun("X", 10.0);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("invalid command"), std::string::npos) << e.what();
  }
}

// A controller that accepts connections and never answers.
class SilentController {
 public:
  SilentController() : acceptor_(io_, {boost::asio::ip::make_address("127.0.0.1"), 0}) {
    accept();
    thread_ = std::thread([this] { io_.run(); });
  }
  ~SilentController() {
    io_.stop();
    thread_.join();
  }
  int port() const { return acceptor_.local_endpoint().port(); }

 private:
  void accept() {
    acceptor_.async_accept([this](boost::system::error_code ec, boost::asio::ip::tcp::socket s) {
      if (!ec)
        held_.push_back(std::move(s));  // kept open, never read, never answered
      accept();
    });
  }
  boost::asio::io_context io_;
  boost::asio::ip::tcp::acceptor acceptor_;
  std::list<boost::asio::ip::tcp::socket> held_;
  std::thread thread_;
};

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

TEST(EnsembleClient, AnInterruptEndsAWaitOnASilentControllerAtOnce) {
  SilentController silent;
  EnsembleClientConfig c;
  c.host = "127.0.0.1";
  c.port = silent.port();
  c.reply_timeout_s = 5.0;
  EnsembleClient client(c);
  auto call = std::async(std::launch::async, [&] { client.position("X"); });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const auto start = std::chrono::steady_clock::now();
  client.interrupt();
  try {
    call.get();
    FAIL() << "no reply, yet no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("interrupted"), std::string::npos) << e.what();
  }
  EXPECT_LT(secondsSince(start), 0.5) << "not retried on a fresh connection either";
  EXPECT_THROW(client.position("X"), Error) << "interrupted until resumed";
}

TEST(StageController, StopsWithinItsDeadlineWhenTheControllerNeverAnswers) {
  SilentController silent;
  StageConfig config;
  config.controller.host = "127.0.0.1";
  config.controller.port = silent.port();
  config.controller.reply_timeout_s = 5.0;
  StageController stage(config);
  auto feedback = std::async(std::launch::async, [&] {
    try {
      stage.feedback();
    } catch (const Error&) {
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const auto start = std::chrono::steady_clock::now();
  stage.interrupt();
  feedback.get();
  stage.stopAll(1.0);
  EXPECT_LT(secondsSince(start), 1.5);  // was 11-13 s: every abort waited its reply timeout
}

TEST(EnsembleClient, NoControllerIsAClearError) {
  EnsembleClientConfig c;
  c.host = "127.0.0.1";
  c.port = 1;
  EnsembleClient client(c);
  try {
    client.position("X");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot connect to 127.0.0.1:1"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace aerotech
}  // namespace dormant_tree_modeling
