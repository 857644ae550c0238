// calibrate_diameters: a scanner's footprint calibration from scans of a reference rig of known
// diameters (RIG.json: the truth schema, the pipe as trunk, the rods as primary branches).
#include <boost/program_options.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "command_line.h"
#include "dormant_tree_modeling/calibration/rig_calibration.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/modeling/tree_model.h"

namespace po = boost::program_options;
using namespace dormant_tree_modeling;

namespace {

/// A rig scan in double precision in the rig file's frame: a cloud (its offset put back) or a
/// folder of views (views.json; each view by its true or registered pose).
calibration::RigScan readRigScan(const std::string& path, const std::string& rig_path) {
  const auto rig = io::readTruthFile(rig_path);
  if (std::filesystem::is_directory(path))
    return calibration::readRigViews(path, rig);
  calibration::RigScan scan;
  scan.name = path;
  scan.rig = rig;
  scan.points = io::readPointsInFileFrame(path);
  return scan;
}

void printSamples(const calibration::RigCalibrationResult& result) {
  std::cerr
      << "part     id  true r mm  apparent mm  noise est mm  noise part mm  footprint mm  scan\n";
  for (const auto& s : result.samples) {
    char line[256];
    std::snprintf(line, sizeof(line), "%-7s %3d  %9.2f  %11.2f  %12.2f  %13.2f  %+12.2f  %s\n",
                  s.trunk ? "section" : "rod", s.index, 1000 * s.radius, 1000 * s.apparent,
                  1000 * s.noise, 1000 * s.noise_part, 1000 * s.footprint(), s.scan.c_str());
    std::cerr << line;
  }
  const auto& c = result.calibration.coverage;
  char line[256];
  std::snprintf(line, sizeof(line),
                "covers: trunk radius %.1f-%.1f mm, branch radius %.1f-%.1f mm, estimated noise "
                "%.2f-%.2f mm\n",
                1000 * c.trunk_radius_min_m, 1000 * c.trunk_radius_max_m,
                1000 * c.branch_radius_min_m, 1000 * c.branch_radius_max_m, 1000 * c.noise_min_m,
                1000 * c.noise_max_m);
  std::cerr << line;
  for (const auto& f : result.branch_floor_reach) {
    std::snprintf(line, sizeof(line),
                  "at %.2f mm of noise the tables cannot tell branches of up to %.1f mm in "
                  "diameter from thinner ones (down to the %.1f mm floor): the modeler reports "
                  "such readings as not measured (diameter_resolved false)\n",
                  1000 * f.noise_m, 2000 * f.radius_m, 2000 * modeling::MIN_BRANCH_RADIUS_M);
    std::cerr << line;
  }
  const auto& s = result.calibration.silhouette;
  if (s.measured) {
    std::snprintf(line, sizeof(line),
                  "silhouette width: %.2f x the diameter + %.2f mm + %.2f mm per m of range "
                  "(rods seen at %.2f-%.2f m); the registration takes %.2f of the margin off for "
                  "the axes' depth\n",
                  s.diameter_gain, 1000 * s.growth_m, 1000 * s.growth_per_m, s.range_min_m,
                  s.range_max_m, s.depth_share);
    std::cerr << line;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> scans, rigs;
  std::string output, params, name = "rig_calibration";
  calibration::RigSearch search;
  po::options_description desc(
      "Usage: calibrate_diameters --scan CLOUD --truth RIG.json [--scan CLOUD --truth RIG.json "
      "...] --output calibration.yaml [--name NAME] [--params FILE]\n"
      "Finds the pipe sections and rods of a reference rig in each scan, measures them with the "
      "modeler's own estimators and noise estimate, takes off what range noise explains and "
      "writes the rest (the beam footprint's widening) as a calibration file for "
      "tree_model --calibration and the tree_modeler node's ~calibration_file");
  desc.add_options()("help,h", "this help")("scan", po::value(&scans)->composing(),
                                            "a scan of the rig (.pcd, .ply, x y z text)")(
      "truth", po::value(&rigs)->composing(),
      "the rig of the --scan before it (truth schema: pipe as trunk, rods as primary_branches; "
      "diameters exact, axes within a few cm, in the scan's frame)")("output,o", po::value(&output),
                                                                     "calibration file to write")(
      "name", po::value(&name)->default_value(name), "the calibration's name (in every model)")(
      "params,p", po::value(&params), "modeler parameters, YAML (the ones the trees will use)")(
      "axis-tolerance-m",
      po::value(&search.axis_tolerance_m)->default_value(search.axis_tolerance_m),
      "how far a rod or section may lie from its axis in the rig file (m)");
  try {
    po::variables_map vm;
    if (tools::parseOrHelp(argc, argv, desc, vm))
      return 0;
    if (scans.empty() || scans.size() != rigs.size() || output.empty())
      throw po::error("give --output and one --truth for each --scan");
    if (!(search.axis_tolerance_m > 0.0 && search.axis_tolerance_m <= 0.5))
      throw po::error("--axis-tolerance-m must be in (0, 0.5]");
    const modeling::ModelerConfig config =
        params.empty() ? modeling::ModelerConfig{} : modeling::loadModelerConfig(params);
    std::vector<calibration::RigScan> rig_scans;
    for (std::size_t i = 0; i < scans.size(); ++i)
      rig_scans.push_back(readRigScan(scans[i], rigs[i]));
    const auto result = calibration::calibrateFromRig(rig_scans, config, name, search);
    printSamples(result);
    for (const auto& w : result.warnings)
      std::cerr << "calibrate_diameters: warning: " << w << "\n";
    std::string comment = "Sensor calibration made by calibrate_diameters from:";
    for (std::size_t i = 0; i < scans.size(); ++i)
      comment += "\n  --scan " + scans[i] + " --truth " + rigs[i];
    io::writeTextFile(output, modeling::sensorCalibrationToYaml(result.calibration, comment));
    std::cout << "calibrate_diameters: " << result.samples.size() << " parts measured in "
              << scans.size() << " scan(s), " << result.warnings.size() << " warning(s) -> "
              << output << "\n";
    return 0;
  } catch (const po::error& e) {
    std::cerr << "calibrate_diameters: " << e.what() << "\n" << desc << "\n";
    return 2;
  } catch (const Error& e) {
    std::cerr << "calibrate_diameters: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    return tools::reportUnexpected("calibrate_diameters", e);
  }
}
