#include "server/node/node.hpp"

#include <boost/asio/write.hpp>

#include "robdef/builtin/service_index.hpp"
#include "server/node/random_ids.hpp"
#include "server/node/service_index.hpp"
#include "server/transport/tcp_listener.hpp"

namespace rr::server {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

std::string tcp_base_url(const tcp::endpoint& local) {
    std::string host = local.address().to_string();
    if (local.address().is_v6()) host = "[" + host.substr(0, host.find('%')) + "]";
    return "rr+tcp://" + host + ":" + std::to_string(local.port()) + "/";
}

std::shared_ptr<Node> Node::create(NodeOptions options) {
    std::shared_ptr<Node> node(new Node(std::move(options)));
    // Built from the built-in definition: cannot fail short of a broken build, and then the node
    // simply has no index (find_service answers ServiceNotFound as before).
    if (auto index = make_service_index(node)) node->service_index_ = std::move(*index);
    node->start_threads();
    return node;
}

Node::Node(NodeOptions options) : options_(std::move(options)) {
    if (options_.node_id.is_any()) options_.node_id = random_node_id();
    if (options_.threads == 0) options_.threads = std::max(2u, std::thread::hardware_concurrency());
    work_ = std::make_unique<asio::executor_work_guard<asio::io_context::executor_type>>(io_.get_executor());
}

Node::~Node() { shutdown(); }

void Node::start_threads() {
    for (unsigned i = 0; i < options_.threads; ++i) threads_.emplace_back([this] { io_.run(); });
}

void Node::shutdown() {
    if (stopped_.exchange(true)) return;
    std::vector<std::shared_ptr<TcpListener>> listeners;
    std::vector<std::weak_ptr<PumpHandle>> pumps;
    {
        std::lock_guard lock(mutex_);
        listeners.swap(listeners_);
        pumps.swap(pumps_);
    }
    for (auto& l : listeners) asio::post(io_, [l] { l->stop(); });
    for (auto& w : pumps)
        if (auto p = w.lock()) p->close();
    work_.reset();
    // Give connections a moment to flush and close, then stop whatever is left (user timers etc.).
    asio::steady_timer stop_timer(io_);
    stop_timer.expires_after(std::chrono::milliseconds(200));
    stop_timer.async_wait([this](boost::system::error_code) { io_.stop(); });
    for (auto& t : threads_)
        if (t.joinable() && t.get_id() != std::this_thread::get_id()) t.join();
    threads_.clear();
}

Result<std::uint16_t> Node::listen_tcp(const std::string& address, std::uint16_t port) {
    boost::system::error_code ec;
    auto addr = asio::ip::make_address(address, ec);
    if (ec) return fail(MessageErrorType::InvalidArgument, "bad listen address \"" + address + "\": " + ec.message());
    tcp::acceptor acceptor(io_);
    tcp::endpoint ep(addr, port);
    acceptor.open(ep.protocol(), ec);
    if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
    if (!ec) acceptor.bind(ep, ec);
    if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (ec)
        return fail(MessageErrorType::IOError,
                    "cannot listen on " + address + ":" + std::to_string(port) + ": " + ec.message());
    auto listener = std::make_shared<TcpListener>(weak_from_this(), std::move(acceptor));
    const std::uint16_t bound = listener->port();
    {
        std::lock_guard lock(mutex_);
        listeners_.push_back(listener);
        listen_endpoints_.emplace_back(addr, bound);
    }
    listener->start();
    return bound;
}

void Node::set_http_handler(HttpHandler handler) {
    std::lock_guard lock(mutex_);
    http_handler_ = std::move(handler);
}

void Node::dispatch_http(tcp::socket socket, std::vector<std::byte> initial) {
    HttpHandler handler;
    {
        std::lock_guard lock(mutex_);
        handler = http_handler_;
    }
    if (handler) {
        handler(std::move(socket), std::move(initial));
        return;
    }
    static constexpr char kNotFound[] = "HTTP/1.1 404 File Not Found\r\nConnection: close\r\nContent-Length: 0\r\n\r\n";
    auto sock = std::make_shared<tcp::socket>(std::move(socket));
    asio::async_write(*sock, asio::buffer(kNotFound, sizeof(kNotFound) - 1), [sock](boost::system::error_code, std::size_t) {
        boost::system::error_code ignored;
        sock->close(ignored);
    });
}

void Node::track(const std::shared_ptr<PumpHandle>& pump) {
    std::lock_guard lock(mutex_);
    if (pumps_.size() > 64 && pumps_.size() % 64 == 0)
        std::erase_if(pumps_, [](const std::weak_ptr<PumpHandle>& w) { return w.expired(); });
    pumps_.push_back(pump);
}

Result<void> Node::register_service(std::shared_ptr<Service> service) {
    const std::string& name = service->name();
    bool valid = !name.empty() && ((name[0] >= 'a' && name[0] <= 'z') || (name[0] >= 'A' && name[0] <= 'Z'));
    for (char c : name)
        valid = valid && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_');
    if (!valid) return fail(MessageErrorType::InvalidArgument, "invalid service name \"" + name + "\"");
    {
        std::lock_guard lock(mutex_);
        if (services_.count(name)) return fail(MessageErrorType::InvalidArgument, "service \"" + name + "\" already registered");
        services_.emplace(name, std::move(service));
    }
    local_node_services_changed(service_index_);
    return {};
}

void Node::unregister_service(const std::string& name) {
    bool erased = false;
    {
        std::lock_guard lock(mutex_);
        erased = services_.erase(name) != 0;
    }
    if (erased) local_node_services_changed(service_index_);
}

std::vector<std::string> Node::service_names() const {
    std::lock_guard lock(mutex_);
    std::vector<std::string> out;
    for (const auto& [n, s] : services_) out.push_back(n);
    return out;
}

std::shared_ptr<Service> Node::find_service(std::string_view name) const {
    std::lock_guard lock(mutex_);
    auto it = services_.find(name);
    if (it != services_.end()) return it->second;
    return name == robdef::kServiceIndexServiceName ? service_index_ : nullptr;
}

std::string Node::listen_base_url() const {
    std::lock_guard lock(mutex_);
    if (listen_endpoints_.empty()) return "rr+tcp://127.0.0.1:0/";
    auto ep = listen_endpoints_.front();
    // A wildcard listener has no one address; loopback is the one every client of this host can use.
    if (ep.address().is_unspecified())
        ep.address(ep.address().is_v6() ? asio::ip::address(asio::ip::address_v6::loopback())
                                         : asio::ip::address(asio::ip::address_v4::loopback()));
    return tcp_base_url(ep);
}

std::uint32_t Node::new_endpoint_id() {
    std::lock_guard lock(mutex_);
    for (;;) {
        std::uint32_t id = random_endpoint_id();
        if (endpoints_.insert(id).second) return id;
    }
}

void Node::release_endpoint_id(std::uint32_t id) {
    std::lock_guard lock(mutex_);
    endpoints_.erase(id);
}

}  // namespace rr::server
