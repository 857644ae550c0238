// register_views: registers a folder of views (views.json + views/*.pcd) without manual input.
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <boost/program_options.hpp>
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "command_line.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/registration/view_folder.h"

namespace po = boost::program_options;
using namespace dormant_tree_modeling;

// Long by design: the options in the order --help lists them, then register and write.
int main(int argc, char** argv) {
  std::string dir, out, params, calibration;
  po::options_description desc(
      "Usage: register_views DIR [--output OUT] [--params registration.yaml] [--calibration FILE] "
      "[--no-hints] "
      "[--no-crop]\n"
      "Registers all views of DIR (views.json, views/<name>.pcd) into the frame of the first "
      "view and writes OUT/registered.pcd, registered.ply, registration.json and "
      "registration.md (OUT defaults to DIR/registered). Exit 0 when every view registered, 1 "
      "when some were left out (listed with the reason), 2 on a bad command line, 3 on "
      "unreadable input");
  desc.add_options()("help,h", "this help")("dir", po::value(&dir)->required(), "folder of views")(
      "output,o", po::value(&out), "output folder")(
      "params,p", po::value(&params), "registration parameters (config/registration.yaml)")(
      "calibration,c", po::value(&calibration),
      "the scanner's calibration file (calibrate_diameters on the rig's views): how much its "
      "beam widens branch silhouettes; without one, an ideal beam")(
      "no-hints",
      "ignore the guessed platform poses: a global search from scratch (slide moves are kept)")(
      "no-crop",
      "register the whole views with the ground (default: 1.2 m around where the guess "
      "expects the tree, ground removed for the registration, kept in registered.pcd)");
  po::positional_options_description pos;
  pos.add("dir", 1);
  try {
    po::variables_map vm;
    if (tools::parseOrHelp(argc, argv, desc, vm, pos))
      return 0;
    if (out.empty())
      out = dir + "/registered";
    registration::RegistrationConfig config;
    if (!params.empty())
      config = registration::loadRegistrationConfig(params);
    if (calibration.empty() || !registration::applySensorCalibration(
                                   modeling::loadSensorCalibration(calibration), config)) {
      std::cerr << "register_views: warning: no silhouette growth calibrated: branch axes assume "
                   "an ideal beam\n";
    }
    if (vm.count("no-hints"))
      config.use_hints = false;
    registration::ViewFolderConfig fo;
    if (vm.count("no-crop")) {
      fo.crop_radius = 0;
      fo.ground_margin = -1;
    }
    fo.use_guesses = config.use_hints;
    const auto folder = registration::readViewFolder(dir, fo);
    std::cout << "register_views: " << folder.views.size() << " views from " << dir << "\n";
    for (const auto& w : folder.warnings)
      std::cerr << "register_views: warning: " << w << "\n";
    const auto result = registration::registerViews(folder.views, config);
    std::optional<registration::PoseErrors> errors;
    const auto e = registration::poseErrors(result, folder.true_poses);
    if (e.views > 0)
      errors = e;
    const Cloud registered = registration::registeredFolderCloud(dir, fo, folder, result);
    registration::writeRegistration(out, registered, result, errors);
    const std::size_t points = registered.size();
    int left_out = 0;
    for (const auto& v : result.views) {
      if (!v.registered) {
        ++left_out;
        std::cerr << "register_views: " << v.name << " left out: " << v.reason << "\n";
      }
    }
    std::cout << std::fixed << std::setprecision(1) << result.views.size() - left_out << " of "
              << result.views.size() << " views registered in " << result.seconds << " s; "
              << points << " points -> " << out << "\n";
    if (errors) {
      std::cout << "pose error vs truth: " << registration::poseErrorText(errors->first_view)
                << " in the first view's frame; " << registration::poseErrorText(errors->aligned)
                << " aligned\n";
    }
    return left_out == 0 ? 0 : 1;
  } catch (const po::error& e) {
    std::cerr << "register_views: " << e.what() << "\n" << desc << "\n";
    return 2;
  } catch (const Error& e) {
    std::cerr << "register_views: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    return tools::reportUnexpected("register_views", e);
  }
}
