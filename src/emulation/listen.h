#pragma once

// Listening sockets of the emulators' servers, private to the emulation area.

#include <boost/asio/ip/tcp.hpp>
#include <string>

namespace dormant_tree_modeling {
namespace emulation {

/// @brief Opens, binds (address reuse on, so a restarted emulator gets its port back) and
/// listens on address:port.
/// @param who names the server in the error ("LMS111 emulator")
/// @throws Error IO_FAILURE "<who> cannot listen on <address>:<port>: <reason>"
void listenOn(boost::asio::ip::tcp::acceptor& acceptor, const std::string& address, int port,
              const std::string& who);

}  // namespace emulation
}  // namespace dormant_tree_modeling
