#include "server/discovery/local_addresses.hpp"

#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>

#include <cstring>

namespace rr::server::discovery {

std::vector<LocalAddress> local_addresses() {
    std::vector<LocalAddress> out;
    ifaddrs* list = nullptr;
    if (getifaddrs(&list) != 0) return out;
    for (ifaddrs* ifa = list; ifa; ifa = ifa->ifa_next) {
        if (!ifa->ifa_addr) continue;
        LocalAddress a;
        a.if_name = ifa->ifa_name ? ifa->ifa_name : "";
        a.if_index = a.if_name.empty() ? 0 : if_nametoindex(a.if_name.c_str());
        a.up = (ifa->ifa_flags & IFF_UP) != 0;
        a.multicast = (ifa->ifa_flags & IFF_MULTICAST) != 0;
        a.loopback = (ifa->ifa_flags & IFF_LOOPBACK) != 0;
        if (ifa->ifa_addr->sa_family == AF_INET) {
            sockaddr_in sin{};
            std::memcpy(&sin, ifa->ifa_addr, sizeof sin);
            boost::asio::ip::address_v4::bytes_type b;
            std::memcpy(b.data(), &sin.sin_addr, 4);
            a.address = boost::asio::ip::address_v4(b);
            if ((ifa->ifa_flags & IFF_BROADCAST) && ifa->ifa_broadaddr) {
                sockaddr_in bc{};
                std::memcpy(&bc, ifa->ifa_broadaddr, sizeof bc);
                std::memcpy(b.data(), &bc.sin_addr, 4);
                a.broadcast = boost::asio::ip::address_v4(b);
            }
        } else if (ifa->ifa_addr->sa_family == AF_INET6) {
            sockaddr_in6 sin6{};
            std::memcpy(&sin6, ifa->ifa_addr, sizeof sin6);
            boost::asio::ip::address_v6::bytes_type b;
            std::memcpy(b.data(), &sin6.sin6_addr, 16);
            a.address = boost::asio::ip::address_v6(b, sin6.sin6_scope_id);
        } else {
            continue;
        }
        out.push_back(std::move(a));
    }
    freeifaddrs(list);
    return out;
}

}  // namespace rr::server::discovery
