#include "server/transport/transport_registry.hpp"

#include "server/transport/local/local_connector.hpp"
#include "server/transport/tcp_connector.hpp"
#include "server/transport/tls/rrs_connector.hpp"
#include "server/transport/websocket_connector.hpp"

namespace rr::server {

TransportRegistry::TransportRegistry() {
    auto tcp = std::make_shared<TcpConnector>();
    connectors_.emplace("rr+tcp", tcp);
    connectors_.emplace("tcp", tcp);
    connectors_.emplace("rr+ws", std::make_shared<WebSocketConnector>(false));
    connectors_.emplace("rr+wss", std::make_shared<WebSocketConnector>(true));
    connectors_.emplace("rrs+tcp", std::make_shared<RrsTcpConnector>());
    connectors_.emplace("rr+local", std::make_shared<local::LocalConnector>());
}

void TransportRegistry::add(std::string scheme, std::shared_ptr<Connector> connector) {
    std::lock_guard lock(mutex_);
    connectors_[std::move(scheme)] = std::move(connector);
}

std::shared_ptr<Connector> TransportRegistry::find(std::string_view scheme) const {
    std::lock_guard lock(mutex_);
    auto it = connectors_.find(scheme);
    return it == connectors_.end() ? nullptr : it->second;
}

std::vector<std::string> TransportRegistry::schemes() const {
    std::lock_guard lock(mutex_);
    std::vector<std::string> out;
    for (const auto& [scheme, c] : connectors_) out.push_back(scheme);
    return out;
}

void TransportRegistry::connect(boost::asio::any_io_executor strand, const ConnectionUrl& url, const ConnectOptions& options,
                                std::shared_ptr<ConnectionLogic> logic, ConnectHandler done) const {
    auto connector = find(url.scheme);
    if (!connector) return done(fail(MessageErrorType::ConnectionError, "no transport for \"" + url.scheme + "\" URLs"));
    connector->connect(std::move(strand), url, options, std::move(logic), std::move(done));
}

TransportRegistry& default_transports() {
    static TransportRegistry registry;
    return registry;
}

}  // namespace rr::server
