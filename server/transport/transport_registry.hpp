// Connectors by URL scheme (transport.hpp). A node owns one (Node::transports()); clients without a
// node use default_transports(). Every registry starts with the built-in transports: rr+tcp (and the
// legacy tcp), rr+ws, rr+wss, rrs+tcp, rr+local.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "server/transport/transport.hpp"

namespace rr::server {

class TransportRegistry {
public:
    /// A registry holding the built-in connectors.
    TransportRegistry();
    /// An empty registry (tests).
    struct Empty {};
    explicit TransportRegistry(Empty) {}

    /// Adds or replaces the connector for `scheme`. Thread-safe.
    void add(std::string scheme, std::shared_ptr<Connector> connector);
    /// The connector for `scheme`, or nullptr. Thread-safe.
    std::shared_ptr<Connector> find(std::string_view scheme) const;
    std::vector<std::string> schemes() const;

    /// Opens a connection to `url` with the connector of its scheme; `done` gets ConnectionError
    /// "no transport for scheme …" when there is none.
    void connect(boost::asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                 std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) const;

private:
    mutable std::mutex mutex_;
    std::map<std::string, std::shared_ptr<Connector>, std::less<>> connectors_;
};

/// The process-wide registry for clients that have no node (the rr CLI, rr::client::Client).
TransportRegistry& default_transports();

}  // namespace rr::server
