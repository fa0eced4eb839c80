#include "server/node/node.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include <boost/asio/steady_timer.hpp>

#include "robdef/builtin/service_index.hpp"
#include "server/common/random_ids.hpp"
#include "server/node/service_index.hpp"

namespace rr::server {

namespace asio = boost::asio;

std::shared_ptr<Node> Node::create(NodeOptions options) {
    std::shared_ptr<Node> node(new Node(std::move(options)));
    node->service_index_ = make_service_index(node);
    node->services_->set_fallback(std::string(robdef::kServiceIndexServiceName), node->service_index_);
    node->start_threads();
    return node;
}

Node::Node(NodeOptions options) : options_(std::move(options)) {
    if (options_.node_id.is_any()) options_.node_id = random_node_id();
    if (options_.threads == 0) options_.threads = std::max(2u, std::thread::hardware_concurrency());
    options_.server.stream.local_node_id = options_.node_id;
    options_.server.stream.local_node_name = options_.node_name;
    service_state_nonce_ = random_service_state_nonce();
    work_ = std::make_unique<asio::executor_work_guard<asio::io_context::executor_type>>(io_.get_executor());
}

Node::~Node() { shutdown(); }

void Node::start_threads() {
    for (unsigned i = 0; i < options_.threads; ++i) threads_.emplace_back([this] { io_.run(); });
}

void Node::shutdown() {
    if (stopped_.exchange(true)) return;
    std::vector<std::shared_ptr<Listener>> listeners;
    std::vector<std::weak_ptr<PumpHandle>> pumps;
    {
        std::lock_guard lock(mutex_);
        listeners.swap(listeners_);
        pumps.swap(pumps_);
    }
    for (auto& l : listeners) l->stop();
    for (auto& w : pumps)
        if (auto p = w.lock()) p->close_going_away();
    work_.reset();
    // Give connections a moment to flush and close, at most 200 ms, less once the io_context has run out
    // of work (a stop with no client busy is quick). Then stop whatever is left (user timers etc.).
    // Ending the moment as soon as the node's connections had gone was too early: what the closes and
    // stops just asked for (a listener's acceptor closing, a client connection of the gateway's ending
    // and freeing its device mirror) still had handlers to run, and stopped unrun they left the port
    // bound and the mirror and its connection holding each other (LeakSanitizer, issue 57).
    const bool on_own_thread = std::any_of(threads_.begin(), threads_.end(),
                                           [](const std::thread& t) { return t.get_id() == std::this_thread::get_id(); });
    asio::steady_timer stop_timer(io_);
    if (on_own_thread) {
        // Cannot wait here (this thread runs the pumps): the moment is a timer, as before.
        stop_timer.expires_after(std::chrono::milliseconds(200));
        stop_timer.async_wait([this](boost::system::error_code) { io_.stop(); });
    } else {
        // io_context::run() returns on every thread, and stopped() turns true, once no work is left.
        const auto give_up = std::chrono::steady_clock::now() + std::chrono::milliseconds(200);
        while (!io_.stopped() && std::chrono::steady_clock::now() < give_up)
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        io_.stop();
    }
    for (auto& t : threads_)
        if (t.joinable() && t.get_id() != std::this_thread::get_id()) t.join();
    threads_.clear();
    // A connection that had not closed within the moment (still flushing to a peer that floods it,
    // or a loaded machine) is closed now: its peer must see the end rather than wait on an open
    // socket until its receive timeout. No thread runs the pumps any more.
    for (auto& w : pumps)
        if (auto p = w.lock()) p->close_now();
}

void Node::add_listener(std::shared_ptr<Listener> listener) {
    std::lock_guard lock(mutex_);
    listeners_.push_back(std::move(listener));
}

std::vector<std::string> Node::listen_urls() const {
    std::lock_guard lock(mutex_);
    std::vector<std::string> out;
    for (const auto& l : listeners_)
        for (auto& u : l->urls()) out.push_back(std::move(u));
    return out;
}

std::string Node::listen_base_url() const {
    std::lock_guard lock(mutex_);
    for (const auto& l : listeners_)
        if (l->scheme() == "rr+tcp") {
            auto urls = l->urls();
            if (!urls.empty()) return urls.front();
        }
    return "rr+tcp://127.0.0.1:0/";
}

std::shared_ptr<ConnectionLogic> Node::open_connection(const AcceptedStream& stream) {
    if (stopped_.load() || !can_accept()) return nullptr;
    ServerConnectionConfig config = options_.server;
    config.peer = stream.peer;
    config.web_login = stream.web_login;
    return std::make_shared<ServerConnection>(services_, stats_, std::move(config), stream.local_url, mono_now());
}

std::unique_ptr<ReadThrottle> Node::make_read_throttle() {
    if (!options_.read_rates.enabled()) return nullptr;
    return std::make_unique<ReadThrottle>(options_.read_rates, ReadThrottle::Clock::now());
}

void Node::read_throttled(const std::string& peer) {
    reads_throttled_.fetch_add(1, std::memory_order_relaxed);
    if (options_.on_throttled) options_.on_throttled(peer);
}

bool Node::can_accept() const {
    return !options_.max_connections || connection_count() < options_.max_connections;
}

void Node::track(const std::shared_ptr<PumpHandle>& pump) {
    std::lock_guard lock(mutex_);
    if (pumps_.size() > 64 && pumps_.size() % 64 == 0)
        std::erase_if(pumps_, [](const std::weak_ptr<PumpHandle>& w) { return w.expired(); });
    pumps_.push_back(pump);
}

Result<void> Node::register_service(std::shared_ptr<Service> service) {
    if (service) service->attach(io_);
    if (auto r = services_->add(std::move(service)); !r) return r;
    services_changed();
    return {};
}

void Node::unregister_service(const std::string& name) {
    if (services_->remove(name)) services_changed();
}

void Node::services_changed() {
    local_node_services_changed(service_index_);
    std::vector<std::shared_ptr<Listener>> listeners;
    std::vector<std::function<void()>> callbacks;
    std::string nonce;
    {
        std::lock_guard lock(mutex_);
        service_state_nonce_ = random_service_state_nonce(service_state_nonce_);
        nonce = service_state_nonce_;
        listeners = listeners_;
        callbacks = services_changed_callbacks_;
    }
    for (const auto& l : listeners) l->services_changed(nonce);
    for (const auto& c : callbacks) c();
}

std::string Node::service_state_nonce() const {
    std::lock_guard lock(mutex_);
    return service_state_nonce_;
}

void Node::on_services_changed(std::function<void()> callback) {
    std::lock_guard lock(mutex_);
    services_changed_callbacks_.push_back(std::move(callback));
}

std::vector<std::string> Node::service_names() const { return services_->names(); }

std::shared_ptr<Service> Node::find_service(std::string_view name) const { return services_->find(name); }

}  // namespace rr::server
