// lms111_emulator: a SICK LMS111 on 127.0.0.1 (CoLa-A and CoLa-B), scanning a synthetic
// orchard, replaying a recorded telegram or a whole recorded session, with fault injection.
#include <boost/program_options.hpp>
#include <iostream>

#include "command_line.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/emulation/lms111_server.h"
#include "dormant_tree_modeling/emulation/session_replay.h"
#include "dormant_tree_modeling/simulation/orchard_generator.h"
#include "dormant_tree_modeling/simulation/simulated_scan_source.h"
#include "serve_loop.h"

namespace po = boost::program_options;
using namespace dormant_tree_modeling;

// Long by design: the options (scene, pose, noise, faults, session) in the order --help lists
// them, then the server.
int main(int argc, char** argv) {
  emulation::LmsServerConfig server;
  emulation::LmsEmulatorConfig device;
  emulation::LmsFaults faults;
  std::string telegram, session, scene_path, preset = "young_tall_spindle";
  std::uint64_t seed = 1;
  double distance = 1.5, height = 1.5, noise_mm = 12.0, frequency = 25.0, duration = 0.0;
  std::vector<std::string> sfa;
  po::options_description desc(
      "Usage: lms111_emulator [options]\n"
      "Serves an emulated SICK LMS111 until SIGINT/SIGTERM (or --duration). Scans come from a "
      "synthetic orchard seen from a fixed pose in front of its target tree, from a recorded "
      "telegram (--telegram), or from a recorded CoLa-B session (--session: recorded replies to "
      "the requests the recorded host sent, the recorded events and scans).");
  desc.add_options()("help,h", "this help")(
      "address", po::value(&server.address)->default_value(server.address), "listen address")(
      "cola-a-port", po::value(&server.cola_a_port)->default_value(server.cola_a_port),
      "CoLa-A port (0: any free one, -1: off)")(
      "cola-b-port", po::value(&server.cola_b_port)->default_value(server.cola_b_port),
      "CoLa-B port (0: any free one, -1: off)")(
      "telegram", po::value(&telegram), "replay this recorded LMDscandata telegram (text file)")(
      "session", po::value(&session),
      "replay this recorded CoLa-B session ('<seconds> <hex>' lines)")(
      "angle-error-units",
      po::value(&device.reported_angle_error)->default_value(device.reported_angle_error),
      "report LMPoutputRange this many 1/10000 deg inside the nominal range, as real units do")(
      "scene", po::value(&scene_path), "scan this scene (scene.json of synth_tree)")(
      "preset", po::value(&preset)->default_value(preset), "synthetic orchard preset")(
      "seed", po::value(&seed)->default_value(seed), "synthetic orchard seed")(
      "distance", po::value(&distance)->default_value(distance),
      "laser distance in front of the tree, m")("height", po::value(&height)->default_value(height),
                                                "laser height, m")(
      "noise-mm", po::value(&noise_mm)->default_value(noise_mm), "range noise, 1 sigma, mm")(
      "frequency", po::value(&frequency)->default_value(frequency),
      "power-up scan frequency, Hz: 25 (0.25 deg) or 50 (0.5 deg)")(
      "spin-up", po::value(&device.spin_up_seconds)->default_value(device.spin_up_seconds),
      "seconds from start of measurement to ready")(
      "drift-ppm", po::value(&device.clock_drift_ppm)->default_value(0.0),
      "device clock error, ppm")("clock-start-us", po::value(&device.clock_start_us),
                                 "device clock at power-up, µs")(
      "drop-after", po::value(&faults.drop_after), "fault: close connections after N telegrams")(
      "stall-after", po::value(&faults.stall_after), "fault: go silent after N telegrams")(
      "stall-seconds", po::value(&faults.stall_seconds)->default_value(faults.stall_seconds),
      "fault: for this long")("trickle-bytes", po::value(&faults.trickle_bytes),
                              "fault: send in pieces of N bytes")(
      "corrupt-every", po::value(&faults.corrupt_every), "fault: corrupt every N-th telegram")(
      "restart-after", po::value(&faults.restart_after), "fault: reboot after N telegrams")(
      "restart-seconds", po::value(&faults.restart_seconds)->default_value(faults.restart_seconds),
      "fault: reboot duration")("sfa", po::value(&sfa)->composing(),
                                "fault: NAME:CODE[:TIMES] answer sFA CODE to command NAME")(
      "duration", po::value(&duration)->default_value(duration), "seconds to run, 0 = forever");
  try {
    auto args = tools::withoutRosArguments(argc, argv);
    po::variables_map vm;
    if (tools::parseOrHelp(static_cast<int>(args.size()), args.data(), desc, vm))
      return 0;
    for (const auto& s : sfa)
      faults.addSfa(s);
    if (frequency != 25.0 && frequency != 50.0)
      throw Error(ErrorCode::INVALID_ARGUMENT, "--frequency must be 25 or 50");
    device.scan.frequency = frequency == 25.0 ? 2500 : 5000;
    device.scan.resolution = device.scan.frequency;
    if (!telegram.empty() && !session.empty())
      throw Error(ErrorCode::INVALID_ARGUMENT, "--telegram and --session exclude each other");
    for (const int port : {server.cola_a_port, server.cola_b_port}) {
      if (port < -1 || port > 65535)
        throw Error(ErrorCode::INVALID_ARGUMENT,
                    "ports must be in 0..65535 (or -1: off), not " + std::to_string(port));
    }
    std::shared_ptr<emulation::EmulatedLms111> emulated;
    std::shared_ptr<emulation::ScanSource> source;
    if (!session.empty()) {
      emulated = emulation::makeSessionReplay(lms111::readSessionFile(session), device, faults);
    } else if (!telegram.empty()) {
      source = std::make_shared<emulation::RecordedScanSource>(
          emulation::RecordedScanSource::fromFile(telegram));
    } else {
      const simulation::Scene scene =
          simulation::sceneFromFileOrPreset(scene_path, preset, seed).scene;
      simulation::Lms111Config sensor;
      sensor.range_noise_sigma = noise_mm / 1000.0;
      const Eigen::Isometry3d pose = simulation::SimulatedScanSource::frontView(distance, height);
      source = std::make_shared<simulation::SimulatedScanSource>(
          scene, [pose](double) { return pose; }, sensor, seed);
    }
    if (!emulated)
      emulated = std::make_shared<emulation::EmulatedLms111>(device, source, faults);
    emulation::LmsServer running(emulated, server);
    std::cout << "lms111_emulator: listening on " << server.address << ", CoLa-A port "
              << running.colaAPort() << ", CoLa-B port " << running.colaBPort() << std::endl;
    tools::serveUntilStopped(duration);
    running.stop();
    std::cout << "lms111_emulator: " << running.connectionsAccepted() << " connections, "
              << running.telegramsSent() << " scan telegrams sent" << std::endl;
    return 0;
  } catch (const po::error& e) {
    std::cerr << "lms111_emulator: " << e.what() << "\n" << desc << "\n";
    return 2;
  } catch (const Error& e) {
    std::cerr << "lms111_emulator: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    return tools::reportUnexpected("lms111_emulator", e);
  }
}
