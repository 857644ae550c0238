#include "listen.h"

#include <boost/asio/ip/address.hpp>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace emulation {

void listenOn(boost::asio::ip::tcp::acceptor& acceptor, const std::string& address, int port,
              const std::string& who) {
  using boost::asio::ip::tcp;
  boost::system::error_code ec;
  const tcp::endpoint endpoint(boost::asio::ip::make_address(address, ec),
                               static_cast<unsigned short>(port));
  if (!ec)
    acceptor.open(endpoint.protocol(), ec);
  if (!ec)
    acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec)
    acceptor.bind(endpoint, ec);
  if (!ec)
    acceptor.listen(boost::asio::socket_base::max_listen_connections, ec);
  if (ec) {
    throw Error(ErrorCode::IO_FAILURE, who + " cannot listen on " + address + ":" +
                                           std::to_string(port) + ": " + ec.message());
  }
}

}  // namespace emulation
}  // namespace dormant_tree_modeling
