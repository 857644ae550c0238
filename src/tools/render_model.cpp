// render_model: a model's cylinders drawn over its cloud, as a PNG (front view: x right, z up).
#include <boost/program_options.hpp>
#include <iostream>

#include "command_line.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/simulation/preview.h"

namespace po = boost::program_options;
using namespace dormant_tree_modeling;

int main(int argc, char** argv) {
  std::string cloud_path, model_path, output;
  int width = 800;
  po::options_description desc(
      "Usage: render_model CLOUD MODEL --output PNG [--width PIXELS]\n"
      "Draws the model's cylinders (trunk brown, primary branches green, pruning candidates "
      "red) over the cloud, seen from -y (x right, z up); cloud and model in one frame.\n"
      "Exit status: 0 written, 2 usage, 3 unreadable input or a model that is not a tree, 7 "
      "cannot write");
  desc.add_options()("help,h", "this help")("cloud", po::value(&cloud_path)->required(),
                                            "PCD, PLY or x y z text")(
      "model", po::value(&model_path)->required(), "model.json")(
      "output,o", po::value(&output)->required(), "PNG to write")(
      "width", po::value(&width)->default_value(width), "image width, pixels");
  po::positional_options_description positional;
  positional.add("cloud", 1).add("model", 1);
  try {
    po::variables_map vm;
    if (tools::parseOrHelp(argc, argv, desc, vm, positional))
      return 0;
    if (width < 100 || width > 8000)
      throw po::error("--width must be within 100..8000");
    io::CloudReadResult cloud;
    modeling::TreeModel model;
    try {
      cloud = io::readCloud(cloud_path);
      model = io::readModelFile(model_path);
    } catch (const Error& e) {
      std::cerr << "render_model: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
      return 3;
    }
    // The cloud may have been recentred (survey coordinates): move the model with it.
    if (!cloud.offset.isZero()) {
      Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
      shift.translation() = -cloud.offset;
      model = modeling::transformModel(model, shift);
    }
    try {
      simulation::renderModelPreview(*cloud.cloud, model, output, width);
    } catch (const Error& e) {
      std::cerr << "render_model: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
      return e.code() == ErrorCode::IO_FAILURE ? 7 : 3;
    }
    return 0;
  } catch (const po::error& e) {
    std::cerr << "render_model: " << e.what() << "\n" << desc << "\n";
    return 2;
  } catch (const Error& e) {
    std::cerr << "render_model: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return 7;
  } catch (const std::exception& e) {
    return tools::reportUnexpected("render_model", e);
  }
}
