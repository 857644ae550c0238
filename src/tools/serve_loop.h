#pragma once

#include <chrono>
#include <csignal>
#include <string>
#include <thread>
#include <vector>

namespace dormant_tree_modeling {
namespace tools {

/// @brief The arguments without those roslaunch appends to a node's command line
/// (`__name:=`, `__log:=`, remappings): the emulators run as launch-file nodes too.
inline std::vector<char*> withoutRosArguments(int argc, char** argv) {
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (i == 0 || std::string(argv[i]).find(":=") == std::string::npos)
      args.push_back(argv[i]);
  }
  return args;
}

namespace detail {
inline volatile std::sig_atomic_t g_stop = 0;
inline void onSignal(int) {
  g_stop = 1;
}
}  // namespace detail

/// @brief Block until SIGINT or SIGTERM, or until `duration_s` passed when it is > 0: the
/// servers run on their own threads meanwhile.
inline void serveUntilStopped(double duration_s) {
  std::signal(SIGINT, detail::onSignal);
  std::signal(SIGTERM, detail::onSignal);
  const auto start = std::chrono::steady_clock::now();
  while (!detail::g_stop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (duration_s > 0 &&
        std::chrono::steady_clock::now() - start > std::chrono::duration<double>(duration_s))
      break;
  }
}

}  // namespace tools
}  // namespace dormant_tree_modeling
