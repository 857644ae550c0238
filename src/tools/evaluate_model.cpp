// evaluate_model: scores models against ground truth as docs/evaluation.md defines.
#include <boost/program_options.hpp>
#include <iostream>

#include "command_line.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/evaluation/matching.h"
#include "dormant_tree_modeling/io/tree_json.h"

namespace po = boost::program_options;
using namespace dormant_tree_modeling;

int main(int argc, char** argv) {
  std::vector<std::string> models, truths;
  po::options_description desc(
      "Usage: evaluate_model --model model.json --truth truth.json [--model M2 --truth T2 ...] "
      "[--json | --details]\n"
      "Prints PB, IPB, FP rate, FN rate, F1, branch and trunk diameter MAE, coverage, runtime");
  desc.add_options()("help,h", "this help")("model,m", po::value(&models)->composing(),
                                            "model JSON (repeatable)")(
      "truth,t", po::value(&truths)->composing(), "truth JSON, paired in order with --model")(
      "json", "machine-readable output")(
      "details",
      "also list each detection (TP, FP, ignored), each missed branch, each trunk "
      "cylinder with its errors");
  try {
    po::variables_map vm;
    if (tools::parseOrHelp(argc, argv, desc, vm))
      return 0;
    if (models.empty() || models.size() != truths.size()) {
      std::cerr << "evaluate_model: give as many --model as --truth (at least one pair)\n";
      return 2;
    }
    std::vector<evaluation::TreeScore> scores;
    for (std::size_t i = 0; i < models.size(); ++i) {
      const auto model = io::readModelFile(models[i]);
      const auto truth = io::readTruthFile(truths[i]);
      auto s = evaluation::evaluate(model, truth);
      s.name = models[i];
      if (vm.count("details"))
        std::cout << evaluation::formatDetails(s, model, truth);
      if (s.name.size() > 28)
        s.name = "..." + s.name.substr(s.name.size() - 25);
      scores.push_back(s);
    }
    std::cout << (vm.count("json") ? evaluation::scoresToJson(scores)
                                   : evaluation::formatTable(scores));
    return 0;
  } catch (const po::error& e) {
    std::cerr << "evaluate_model: " << e.what() << "\n";
    return 2;
  } catch (const Error& e) {
    std::cerr << "evaluate_model: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    return tools::reportUnexpected("evaluate_model", e);
  }
}
