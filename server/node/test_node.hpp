// Test-only: a node for in-process tests, with a NodeName and two I/O threads (so a handler that
// blocks one thread does not stall the other connections).
#pragma once

#include <memory>
#include <string>
#include <utility>

#include "server/node/node.hpp"

namespace rr::server::testing {

inline std::shared_ptr<Node> test_node(std::string name) {
    NodeOptions o;
    o.node_name = std::move(name);
    o.threads = 2;
    return Node::create(std::move(o));
}

}  // namespace rr::server::testing
