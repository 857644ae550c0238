// virtual_platform: the scanning platform without hardware. Serves an LMS111 (CoLa-A and
// CoLa-B) and an Aerotech Ensemble (rotary stage X in deg, slide Y in mm) on 127.0.0.1 from
// one synthetic orchard: the laser scans from the pose the emulated stage is in, so the
// driver, stage controller and scan assembler run unchanged against it.
#include <boost/program_options.hpp>
#include <iostream>

#include "command_line.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/simulation/orchard_generator.h"
#include "dormant_tree_modeling/simulation/virtual_platform.h"
#include "serve_loop.h"

namespace po = boost::program_options;
using namespace dormant_tree_modeling;

int main(int argc, char** argv) {
  lms111::EmulatorServerOptions lms;
  int aerotech_port = 8000;
  std::string scene_path, preset = "young_tall_spindle";
  std::uint64_t seed = 1;
  double noise_mm = 12.0, frequency = 25.0, duration = 0.0;
  std::vector<double> platform = {0.0, -1.5, 1.5, 90.0};
  aerotech::EnsembleFaults faults;
  po::options_description desc(
      "Usage: virtual_platform [options]\n"
      "Serves an emulated LMS111 and Aerotech Ensemble on 127.0.0.1 until SIGINT/SIGTERM: the "
      "laser scans a synthetic orchard from the pose of the emulated rotary stage (X, deg) and "
      "slide (Y, mm) on a platform at --platform.");
  desc.add_options()("help,h", "this help")(
      "lms-port", po::value(&lms.cola_a_port)->default_value(lms.cola_a_port),
      "LMS111 CoLa-A port (0: any, -1: off)")(
      "lms-b-port", po::value(&lms.cola_b_port)->default_value(lms.cola_b_port),
      "LMS111 CoLa-B port (0: any, -1: off)")(
      "aerotech-port", po::value(&aerotech_port)->default_value(aerotech_port), "Ensemble port")(
      "scene", po::value(&scene_path), "scan this scene (scene.json of synth_tree)")(
      "preset", po::value(&preset)->default_value(preset), "synthetic orchard preset")(
      "seed", po::value(&seed)->default_value(seed), "synthetic orchard seed")(
      "noise-mm", po::value(&noise_mm)->default_value(noise_mm), "range noise, 1 sigma, mm")(
      "frequency", po::value(&frequency)->default_value(frequency),
      "LMS111 power-up frequency, Hz (25 or 50)")(
      "platform", po::value(&platform)->multitoken(),
      "platform pose in the tree frame: x y z yaw_deg (default 0 -1.5 1.5 90: in front of the "
      "tree, facing it, laser at 1.5 m)")("fault-axis", po::value(&faults.fault_axis),
                                          "fault: this stage axis faults ...")(
      "fault-on-move", po::value(&faults.fault_on_move), "... half-way through its N-th move")(
      "duration", po::value(&duration)->default_value(duration), "seconds to run, 0 = forever");
  try {
    auto args = tools::withoutRosArguments(argc, argv);
    po::variables_map vm;
    if (tools::parseOrHelp(static_cast<int>(args.size()), args.data(), desc, vm))
      return 0;
    if (platform.size() != 4)
      throw Error(ErrorCode::INVALID_ARGUMENT, "--platform takes x y z yaw_deg");

    const simulation::Scene scene = simulation::sceneFromFileOrPreset(scene_path, preset, seed);
    simulation::VirtualPlatformOptions o;
    o.laser = lms;
    o.stage_port = aerotech_port;
    o.scan_frequency_hz = frequency;
    o.range_noise_sigma = noise_mm / 1000.0;
    o.seed = seed;
    o.platform =
        acquisition::platformPose(platform[0], platform[1], platform[2], platform[3] * M_PI / 180);
    o.stage_faults = faults;
    simulation::VirtualPlatform vp(scene, o);
    std::cout << "virtual_platform: LMS111 on 127.0.0.1:" << vp.laserPort() << " (CoLa-A), "
              << vp.laserColaBPort() << " (CoLa-B); Aerotech on 127.0.0.1:" << vp.stagePort()
              << std::endl;
    tools::serveUntilStopped(duration);
    vp.stop();
    return 0;
  } catch (const po::error& e) {
    std::cerr << "virtual_platform: " << e.what() << "\n" << desc << "\n";
    return 2;
  } catch (const Error& e) {
    std::cerr << "virtual_platform: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return 3;
  }
}
