// tree_model: the tree modeler on a cloud file. Exit codes are documented in the README and --help.
#include <boost/program_options.hpp>
#include <iostream>
#include <map>

#include "command_line.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/cylinder_csv.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/modeling/tree_modeler.h"
#include "dormant_tree_modeling/simulation/preview.h"

namespace po = boost::program_options;
using namespace dormant_tree_modeling;

namespace {

/// Exit status of every failure category, as the README lists them.
int exitCode(ErrorCode code) {
  switch (code) {
    case ErrorCode::FILE_NOT_FOUND:
    case ErrorCode::UNKNOWN_FORMAT:
    case ErrorCode::PARSE_ERROR:
      return 3;
    case ErrorCode::EMPTY_INPUT:
      return 4;
    case ErrorCode::NO_TRUNK:
      return 5;
    case ErrorCode::INVALID_ARGUMENT:
      return 6;
    case ErrorCode::IO_FAILURE:
      return 7;
  }
  return 1;
}

}  // namespace

// Long by design: the options in the order --help lists them, then model, write and the
// verbose report, each a few lines.
int main(int argc, char** argv) {
  std::string input, output, params, csv, turned_down, picture, calibration;
  po::options_description desc(
      "Usage: tree_model INPUT --output model.json [--params FILE] [--csv FILE] [--turned-down "
      "FILE] [--picture PNG] [--calibration FILE] [--paper]\n"
      "Models the trunk and primary branches of the tree in INPUT (.pcd, .ply, or x y z text)");
  desc.add_options()("help,h", "this help")("input", po::value(&input), "input cloud")(
      "output,o", po::value(&output), "model JSON to write (docs/evaluation.md)")(
      "params,p", po::value(&params), "modeler parameters, YAML (config/tree_modeler.yaml)")(
      "calibration,c", po::value(&calibration),
      "the scanner's diameter calibration (calibrate_diameters; config/calibration/). Without "
      "one, radii are corrected for range noise only")("csv", po::value(&csv),
                                                       "also write the cylinders as CSV")(
      "turned-down", po::value(&turned_down),
      "also write the branch candidates turned down, where and why, as CSV")(
      "picture", po::value(&picture), "also render the cylinders over the cloud (front view, PNG)")(
      "paper", "the paper's method only (every improvement switched off), for comparisons")(
      "verbose,v", "print stage timings and diagnostics to stderr");
  po::positional_options_description positional;
  positional.add("input", 1);
  try {
    po::variables_map vm;
    if (tools::parseOrHelp(argc, argv, desc, vm, positional))
      return 0;
    if (input.empty() || output.empty()) {
      std::cerr << "tree_model: INPUT and --output are required\n" << desc << "\n";
      return 2;
    }
    modeling::ModelerConfig config =
        vm.count("paper") ? modeling::ModelerConfig::paper() : modeling::ModelerConfig{};
    if (!params.empty())
      config = modeling::loadModelerConfig(params);
    if (!calibration.empty())
      config.calibration = modeling::loadSensorCalibration(calibration);
    const modeling::TreeModeler modeler(config);
    io::CloudReadResult cloud;
    try {
      cloud = io::readCloud(input);
    } catch (const Error& e) {
      if (e.code() != ErrorCode::IO_FAILURE)
        throw;
      // An input the system will not let us read is unreadable input, not an output failure.
      std::cerr << "tree_model: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
      return 3;
    }
    if (cloud.dropped_non_finite > 0) {
      std::cerr << "tree_model: dropped " << cloud.dropped_non_finite << " NaN/Inf points\n";
    }
    const auto result = modeler.model(*cloud.cloud);
    for (const auto& w : result.notices)
      std::cerr << "tree_model: warning: " << w << "\n";
    for (const auto& w : result.model.correction.warnings)
      std::cerr << "tree_model: warning: " << w << "\n";
    io::writeTextFile(output, io::modelToJson(result.model, cloud.offset));
    if (!csv.empty())
      io::writeTextFile(csv, io::cylindersToCsv(result.model, cloud.offset));
    if (!turned_down.empty())
      io::writeTextFile(turned_down, io::turnedDownToCsv(result.rejected_branches, cloud.offset));
    if (!picture.empty())
      simulation::renderModelPreview(*cloud.cloud, result.model, picture);
    if (vm.count("verbose")) {
      std::cerr << "tree_model: " << result.points.size() << " points modeled, noise sigma "
                << 1000.0 * result.noise_sigma << " mm, e_t " << 1000.0 * result.split_error
                << " mm, structure dimension " << result.structure_dimension << ", "
                << result.clusters << " clusters (" << result.trunk_clusters << " trunk, "
                << result.primary_clusters << " primary)\n";
      const auto& pre = result.preprocess;
      std::cerr << "  preprocessing: " << pre.input << " points, " << pre.far_outliers
                << " far outliers, " << pre.after_voxel << " after downsampling, then dropped "
                << pre.floating << " floating, " << pre.ground << " ground, " << pre.wires
                << " on wires, " << pre.capped << " merged by a coarser grid\n";
      for (const auto& t : result.timings)
        std::cerr << "  " << t.first << ": " << t.second << " s\n";
      std::map<std::string, int> reasons;
      for (const auto& r : result.rejected_branches)
        ++reasons[r.text()];
      std::cerr << "  branch candidates turned down:";
      for (const auto& [reason, n] : reasons)
        std::cerr << " " << reason << " " << n << ";";
      std::cerr << "\n";
      for (const auto& c : result.trunk_candidates) {
        std::cerr << "  trunk candidate " << (c.from_column ? "(density column) " : "") << "at ("
                  << c.start.x() << ", " << c.start.y() << ", " << c.start.z() << ") r "
                  << 1000.0 * c.start_radius << " mm: " << c.slices << " circles, z " << c.bottom
                  << ".." << c.top << ", median r " << 1000.0 * c.median_radius << " mm, score "
                  << c.score << (c.slices > 0 && c.pole ? " (pole)" : "") << ", trunk " << c.group
                  << (c.chosen ? "  <- trunk" : "") << (c.other_column ? "  <- another column" : "")
                  << "\n";
      }
      std::cerr << "  " << result.column_points
                << " points on other upright columns left out of the branch search, "
                << result.trunk_column_points << " of them within the trunk's reach left out of "
                << "its cylinders too\n";
    }
    std::cout << "tree_model: " << result.model.trunk.size() << " trunk cylinders, "
              << result.model.primary_branches.size() << " primary branches in "
              << result.model.runtime_s << " s -> " << output << "\n";
    return 0;
  } catch (const po::error& e) {
    std::cerr << "tree_model: " << e.what() << "\n";
    return 2;
  } catch (const Error& e) {
    std::cerr << "tree_model: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return exitCode(e.code());
  } catch (const std::exception& e) {
    return tools::reportUnexpected("tree_model", e);
  }
}
