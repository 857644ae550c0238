// synth_tree: a synthetic orchard around one tree, scanned with the paper's view plan.
#include <boost/program_options.hpp>
#include <iostream>

#include "command_line.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/simulation/dataset.h"

namespace po = boost::program_options;
using namespace dormant_tree_modeling;

int main(int argc, char** argv) {
  simulation::DatasetConfig opt;
  std::string out, views;
  double noise_mm = 12.0, resolution = 0.25;
  std::string sensor = "ours";
  po::options_description desc(
      "Usage: synth_tree --preset NAME --seed N --out DIR [options]\n"
      "Writes scene.json, truth.json, views.json, views/, merged.pcd/.ply, target.pcd, "
      "preview.png");
  desc.add_options()("help,h", "this help")(
      "preset", po::value(&opt.orchard.preset)->default_value(opt.orchard.preset),
      "young_tall_spindle | mature_tall_spindle | central_leader; scored-only variants "
      "crooked_leader | drooping_scaffolds | steep_scaffolds | sparse_whorls | dense_whorls; "
      "calibration_rig (pipe sections "
      "and rods of known diameters; truth.json is its RIG.json for calibrate_diameters)")(
      "seed", po::value(&opt.seed)->default_value(opt.seed), "random seed")(
      "out", po::value(&out)->required(), "output directory (created)")(
      "noise-mm", po::value(&noise_mm)->default_value(noise_mm), "range noise, 1 sigma, mm")(
      "views", po::value(&views), "view plan YAML (default: the paper's 40 views)")(
      "resolution", po::value(&resolution)->default_value(resolution),
      "angular resolution, deg: 0.25 (25 Hz) or 0.5 (50 Hz)")(
      "sensor", po::value(&sensor)->default_value(sensor),
      "sensor physics: ours | thin_beam (no footprint widening) | wide_beam | far_noise (noise "
      "growing with range, more mixed pixels)")(
      "no-clutter", "target tree only: no neighbours, rows, wires or post")(
      "no-view-files", "skip the per-view range images and clouds")(
      "threads", po::value(&opt.threads)->default_value(0), "worker threads, 0 = all cores");
  try {
    po::variables_map vm;
    if (tools::parseOrHelp(argc, argv, desc, vm))
      return 0;
    opt.sensor = simulation::sensorVariant(sensor);
    opt.sensor.range_noise_sigma = noise_mm / 1000.0;
    opt.sensor.angular_resolution_deg = resolution;
    opt.sensor.scan_frequency_hz = resolution == 0.5 ? 50.0 : 25.0;
    if (vm.count("views"))
      opt.plan = acquisition::loadViewPlan(views);
    if (vm.count("no-clutter")) {
      opt.orchard.neighbours = opt.orchard.other_rows = opt.orchard.wires = opt.orchard.post =
          false;
    }
    opt.write_views = !vm.count("no-view-files");
    const auto s = simulation::writeDataset(opt, out);
    std::cout << "synth_tree: " << opt.orchard.preset << " seed " << opt.seed << ": " << s.views
              << " views, " << s.merged_points << " points (" << s.target_points
              << " in target.pcd), " << s.primary_branches << " primary branches, "
              << s.simulate_seconds << " s -> " << out << "\n";
    return 0;
  } catch (const po::error& e) {
    std::cerr << "synth_tree: " << e.what() << "\n" << desc << "\n";
    return 2;
  } catch (const Error& e) {
    std::cerr << "synth_tree: " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    return tools::reportUnexpected("synth_tree", e);
  }
}
