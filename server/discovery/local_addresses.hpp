// The machine's interface addresses (getifaddrs), for node discovery: which IPv6 link-local scopes to
// join FF02::BA86 on and send from, and what to announce when the node listens on a wildcard address.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <boost/asio/ip/address.hpp>

namespace rr::server::discovery {

struct LocalAddress {
    boost::asio::ip::address address;  ///< IPv6 ones carry their scope id (interface index)
    unsigned if_index = 0;
    std::string if_name;
    bool up = false;
    bool multicast = false;
    bool loopback = false;
    boost::asio::ip::address_v4 broadcast;  ///< IPv4 broadcast address of the interface ("" when none)
};

/// Every address of every interface. Empty when getifaddrs fails.
std::vector<LocalAddress> local_addresses();

}  // namespace rr::server::discovery
