// aerotech_emulator: an Aerotech Ensemble on 127.0.0.1 with a rotary stage (X, deg) and a
// linear slide (Y, mm), with fault injection for tests.
#include <boost/program_options.hpp>
#include <iostream>

#include "command_line.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/emulation/ensemble_server.h"
#include "serve_loop.h"

namespace po = boost::program_options;
using namespace dormant_tree_modeling;

int main(int argc, char** argv) {
  std::string address = "127.0.0.1";
  int port = 8000;
  double duration = 0.0;
  emulation::EnsembleFaults faults;
  std::vector<std::string> invalid;
  po::options_description desc(
      "Usage: aerotech_emulator [options]\n"
      "Serves an emulated Aerotech Ensemble (ASCII, one command a line) until SIGINT/SIGTERM: "
      "axis X a rotary stage in deg, axis Y a 600 mm slide in mm.");
  desc.add_options()("help,h", "this help")("address", po::value(&address)->default_value(address),
                                            "listen address")(
      "port", po::value(&port)->default_value(port), "port (0: any free one)")(
      "fault-axis", po::value(&faults.fault_axis), "fault: this axis faults ...")(
      "fault-on-move", po::value(&faults.fault_on_move), "... half-way through its N-th move")(
      "fault-bits", po::value(&faults.fault_bits)->default_value(faults.fault_bits),
      "... with these AXISFAULT bits (1: position error)")(
      "drop-after", po::value(&faults.drop_after_commands),
      "fault: close the socket after N commands")("idle-timeout", po::value(&faults.idle_timeout_s),
                                                  "close sockets idle this long, s")(
      "invalid", po::value(&invalid)->composing(), "fault: answer '!' to this command word")(
      "duration", po::value(&duration)->default_value(duration), "seconds to run, 0 = forever");
  try {
    auto args = tools::withoutRosArguments(argc, argv);
    po::variables_map vm;
    if (tools::parseOrHelp(static_cast<int>(args.size()), args.data(), desc, vm))
      return 0;
    if (port < 0 || port > 65535)
      throw Error(ErrorCode::INVALID_ARGUMENT,
                  "--port must be in 0..65535, not " + std::to_string(port));
    faults.invalid_commands.insert(invalid.begin(), invalid.end());
    auto controller =
        std::make_shared<emulation::EmulatedEnsemble>(emulation::defaultStageAxes(), faults);
    emulation::EnsembleServer server(controller, address, port);
    std::cout << "aerotech_emulator: listening on " << address << ":" << server.port() << std::endl;
    tools::serveUntilStopped(duration);
    server.stop();
    std::cout << "aerotech_emulator: " << server.connectionsAccepted() << " connections"
              << std::endl;
    return 0;
  } catch (const po::error& e) {
    std::cerr << "aerotech_emulator: " << e.what() << "\n" << desc << "\n";
    return 2;
  } catch (const Error& e) {
    std::cerr << "aerotech_emulator: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    return tools::reportUnexpected("aerotech_emulator", e);
  }
}
