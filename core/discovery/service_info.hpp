// Discovery records (official CORE Discovery.h): NodeInfo2 (a node found on the network) and ServiceInfo2
// (one service of it, from RobotRaconteurServiceIndex.GetLocalNodeServices(), wire.md §11.2).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "base/error/rr_error.hpp"
#include "base/names/node_id.hpp"
#include "core/value/value.hpp"

namespace rr::discovery {

/// A node: its NodeID, NodeName ("" = none) and connection URLs (each `…?nodeid=…&service=RobotRaconteurServiceIndex`).
struct NodeInfo2 {
    NodeID node_id;
    std::string node_name;
    std::vector<std::string> connection_urls;
};

/// One service of a node, as CORE's ServiceInfo2.
struct ServiceInfo2 {
    std::string name;                              ///< service name
    std::string root_object_type;                  ///< qualified type of the root object
    std::vector<std::string> root_object_implements;  ///< qualified types the root implements
    std::vector<std::string> connection_urls;      ///< URLs that reach this service
    MapString attributes;                          ///< the service's attributes (varvalue{string})
    NodeID node_id;
    std::string node_name;
};

/// Bounds on what one node's service index may hand us (a hostile node must not grow memory).
struct ServiceInfoLimits {
    std::size_t max_services = 256;
    std::size_t max_string = 1024;       ///< any name, type or URL
    std::size_t max_list = 64;           ///< implements / URLs per service
    std::size_t max_attributes = 64;     ///< attributes per service
};

/// Converts the return value of GetLocalNodeServices() (a MapInt32 of
/// `RobotRaconteurServiceIndex.ServiceInfo` structures) into ServiceInfo2 records for `node`.
/// Entries are taken in key order. Errors: DataTypeMismatch when the value is not such a map or a
/// field has the wrong kind; OutOfRange when a limit is passed.
Result<std::vector<ServiceInfo2>> service_infos_from_value(const Value& value, const NodeID& node_id,
                                                           const std::string& node_name,
                                                           const ServiceInfoLimits& limits = {});

/// The URL scheme of `url` (text before "://"), or "".
std::string url_scheme(std::string_view url);

}  // namespace rr::discovery
