// JSON views of discovery records, shared by `rr discover --json` and the gateway's JSON API
// (docs/discovery.md, docs/json-api.md):
//   node     {"nodeid", "nodename", "urls": [..], "source", "nonce", "services": [service…] | null, "error"}
//   service  {"name", "nodename", "nodeid", "root_object_type", "implements": [..], "urls": [..],
//             "attributes": {name: varvalue JSON (docs/json-mapping.md)}}
#pragma once

#include <nlohmann/json.hpp>

#include "core/discovery/node_table.hpp"

namespace rr::server::discovery {

nlohmann::json service_json(const rr::discovery::ServiceInfo2& service);
nlohmann::json node_json(const rr::discovery::NodeEntry& node);

}  // namespace rr::server::discovery
