// calibrate_diameters: the trunk radius calibration of the modeler, from reference poles
// scanned with the LMS111 model and the view plan. Prints the YAML keys for
// config/tree_modeler.yaml and the samples behind them.
#include <boost/program_options.hpp>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "command_line.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/simulation/branch_calibration.h"

namespace po = boost::program_options;
using namespace dormant_tree_modeling;

namespace {

std::vector<double> parseList(const std::string& text, double scale) {
  std::vector<double> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    std::size_t used = 0;
    const double v = std::stod(item, &used);
    if (used != item.size())
      throw po::error("not a number: '" + item + "'");
    out.push_back(v * scale);
  }
  return out;
}

void printSamples(const char* what, const simulation::TrunkCalibrationResult& result) {
  std::cerr << what << ":\n  radius mm  sensor noise mm  apparent mm  bias mm  noise estimate mm\n";
  for (const auto& s : result.samples) {
    char line[160];
    std::snprintf(line, sizeof(line), "  %9.1f  %15.1f  %11.2f  %+7.2f  %17.2f\n", 1000 * s.radius,
                  1000 * s.sensor_noise, 1000 * s.apparent, 1000 * (s.apparent - s.radius),
                  1000 * s.noise_estimate);
    std::cerr << line;
  }
}

std::string yamlList(const std::vector<double>& v) {
  std::string s = "[";
  char buf[32];
  for (std::size_t i = 0; i < v.size(); ++i) {
    std::snprintf(buf, sizeof(buf), "%s%.5f", i ? ", " : "", v[i]);
    s += buf;
  }
  return s + "]";
}

}  // namespace

int main(int argc, char** argv) {
  simulation::TrunkCalibrationOptions opt;
  std::string radii_mm = "5,7.5,10,15,20,30,45,70,100",
              branch_radii_mm = "3,4,5,6.5,8,10,12.5,15,20", noise_mm = "3,6,12", params, output,
              only;
  po::options_description desc(
      "Usage: calibrate_diameters [--radii-mm LIST] [--branch-radii-mm LIST] [--noise-mm LIST] "
      "[--only trunk|branch] [--params FILE] [--output FILE]\n"
      "Scans reference poles (trunk) and a reference tree of rods (branches) with the LMS111 "
      "model and the 40-view plan, measures them with the modeler and prints the "
      "trunk_calibration_* and branch_calibration_* keys of config/tree_modeler.yaml");
  desc.add_options()("help,h", "this help")(
      "radii-mm", po::value(&radii_mm)->default_value(radii_mm), "pole radii, mm, ascending")(
      "branch-radii-mm", po::value(&branch_radii_mm)->default_value(branch_radii_mm),
      "rod radii, mm, ascending")("only", po::value(&only), "trunk or branch: one table only")(
      "noise-mm", po::value(&noise_mm)->default_value(noise_mm),
      "range noise levels, mm, ascending")("params,p", po::value(&params),
                                           "modeler parameters, YAML (its trunk step settings)")(
      "output,o", po::value(&output), "also write the keys to this file")(
      "threads", po::value(&opt.threads)->default_value(0), "worker threads, 0 = all cores");
  try {
    po::variables_map vm;
    if (tools::parseOrHelp(argc, argv, desc, vm))
      return 0;
    if (!only.empty() && only != "trunk" && only != "branch")
      throw po::error("--only takes trunk or branch");
    opt.noise = parseList(noise_mm, 1e-3);
    if (!params.empty())
      opt.modeler = modeling::loadModelerConfig(params);
    std::string yaml = "  # calibrate_diameters --radii-mm " + radii_mm + " --branch-radii-mm " +
                       branch_radii_mm + " --noise-mm " + noise_mm + "\n";
    auto append = [&](const std::string& key, const modeling::RadiusCalibration& c) {
      yaml += "  " + key + "_radii: " + yamlList(c.radii) + "\n  " + key +
              "_noise: " + yamlList(c.noise) + "\n  " + key + "_bias: " + yamlList(c.bias) + "\n";
    };
    if (only != "branch") {
      opt.radii = parseList(radii_mm, 1e-3);
      const auto trunk = simulation::calibrateTrunkRadii(opt);
      printSamples("trunk", trunk);
      append("trunk_calibration", trunk.calibration);
    }
    if (only != "trunk") {
      opt.radii = parseList(branch_radii_mm, 1e-3);
      const auto branch = simulation::calibrateBranchRadii(opt);
      printSamples("branch", branch);
      append("branch_calibration", branch.calibration);
    }
    std::cout << yaml;
    if (!output.empty())
      io::writeTextFile(output, yaml);
    return 0;
  } catch (const po::error& e) {
    std::cerr << "calibrate_diameters: " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "calibrate_diameters: not a number in a list\n";
    return 2;
  } catch (const Error& e) {
    std::cerr << "calibrate_diameters: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    return tools::reportUnexpected("calibrate_diameters", e);
  }
}
