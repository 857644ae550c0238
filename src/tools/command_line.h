#pragma once

#include <cxxabi.h>

#include <boost/program_options.hpp>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <memory>
#include <string>
#include <typeinfo>

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

/// @brief Exit status of a tool for an exception nothing more specific caught.
constexpr int EXIT_UNEXPECTED = 1;

/// @brief The last handler of every tool's main: reports the exception's type and message and
/// returns EXIT_UNEXPECTED, so that no exception ends a tool with an abort.
inline int reportUnexpected(const char* tool, const std::exception& e) {
  int status = 0;
  const std::unique_ptr<char, void (*)(void*)> name(
      abi::__cxa_demangle(typeid(e).name(), nullptr, nullptr, &status), std::free);
  std::cerr << tool << ": unexpected " << (status == 0 ? name.get() : typeid(e).name()) << ": "
            << e.what() << "\n";
  return EXIT_UNEXPECTED;
}

}  // namespace tools
}  // namespace dormant_tree_modeling
