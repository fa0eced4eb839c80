// The node's built-in `RobotRaconteurServiceIndex` service (robdef.md §13; wire.md §11.2), served by
// every node as CORE does: discovery and `rr info` without `service=` connect to it and call
// GetLocalNodeServices() to list a node's services.
//   GetLocalNodeServices()  one ServiceInfo per registered service plus the index itself, keys 0,1,…
//                           in name order; ConnectionURL {1: <base URL of the transport the request came
//                           in on>?nodeid=<id>&service=<name>}; Attributes: only array-valued entries
//   GetRoutedNodes(), GetDetectedNodes()  empty maps (deprecated, as in CORE)
//   LocalNodeServicesChanged              sent to the index's clients when a service is registered or
//                                         unregistered (local_node_services_changed)
// Implemented at the message-entry level on core/value's packing, so the node needs no typed-service
// framework.
#pragma once

#include <memory>

#include "server/node/service.hpp"

namespace rr::server {

class Node;

/// The service index of `node` (held weakly: the node owns the service).
std::shared_ptr<Service> make_service_index(std::weak_ptr<Node> node);

/// Sends LocalNodeServicesChanged to the clients of `index` (one made by make_service_index; others
/// are ignored).
void local_node_services_changed(const std::shared_ptr<Service>& index);

}  // namespace rr::server
