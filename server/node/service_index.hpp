// The built-in `RobotRaconteurServiceIndex` service of a node (wire.md §11.2, robdef.md §13): discovery
// and `rr info` without `service=` connect to it and call GetLocalNodeServices() to list a node's services.
//
//   GetLocalNodeServices()  one ServiceInfo per registered service plus the index itself, keys 0,1,…
//                           in name order: Name, RootObjectType, RootObjectImplements (keys 0..n−1),
//                           ConnectionURL {1: `<base>?nodeid=<id>&service=<name>`} with the base of the
//                           transport the request came in on (SessionRef::local_url, else the node's
//                           first TCP listener), Attributes (only string / numeric array values, as CORE).
//   GetRoutedNodes(), GetDetectedNodes()   empty maps (deprecated; CORE's routed list is empty too).
//   LocalNodeServicesChanged              fired to the index's clients when a service is registered or
//                                         unregistered (local_node_services_changed).
#pragma once

#include <memory>

#include "core/error/rr_error.hpp"
#include "server/service/service.hpp"

namespace rr::server {

class Node;

/// The service index of `node` (held weakly: the node owns the service). Errors: those of building the
/// typed service from the built-in definition (not expected).
Result<std::shared_ptr<Service>> make_service_index(std::weak_ptr<Node> node);

/// Fires LocalNodeServicesChanged on `index` (one made by make_service_index; others are ignored).
void local_node_services_changed(const std::shared_ptr<Service>& index);

}  // namespace rr::server
