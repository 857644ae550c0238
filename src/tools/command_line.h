#pragma once

#include <boost/program_options.hpp>
#include <iostream>

namespace dormant_tree_modeling {
namespace tools {

/// @brief Parse the command line into `vm` (positional arguments as `positional` says); with
/// --help, print `desc` and return true: the tool then exits 0. Throws boost's po::error for
/// a bad command line (unknown option, missing value, missing required option), which the
/// tools answer with their usage and exit 2.
inline bool parseOrHelp(int argc, char** argv,
                        const boost::program_options::options_description& desc,
                        boost::program_options::variables_map& vm,
                        const boost::program_options::positional_options_description& positional =
                            boost::program_options::positional_options_description()) {
  namespace po = boost::program_options;
  po::store(po::command_line_parser(argc, argv).options(desc).positional(positional).run(), vm);
  if (vm.count("help")) {
    std::cout << desc << "\n";
    return true;
  }
  po::notify(vm);
  return false;
}

}  // namespace tools
}  // namespace dormant_tree_modeling
