#include "server/discovery/node_discovery.hpp"

#include <algorithm>
#include <array>
#include <set>
#include <thread>

#include <boost/asio/bind_executor.hpp>
#include <boost/asio/ip/multicast.hpp>
#include <boost/asio/ip/v6_only.hpp>
#include <boost/asio/post.hpp>

#include "core/discovery/discovery_packet.hpp"
#include "base/names/connection_url.hpp"
#include "server/client/client.hpp"
#include "server/common/random_ids.hpp"
#include "server/discovery/local_addresses.hpp"

namespace rr::server::discovery {

namespace asio = boost::asio;
using udp = asio::ip::udp;
namespace core = rr::discovery;

namespace {

constexpr std::chrono::seconds kRescanPeriod{5};

core::IpAddress to_core(const asio::ip::address& a) {
    core::IpAddress out;
    if (a.is_v4()) {
        auto b = a.to_v4().to_bytes();
        out = core::IpAddress::v4_from(b[0], b[1], b[2], b[3]);
    } else {
        out.v6 = true;
        auto b = a.to_v6().to_bytes();
        std::copy(b.begin(), b.end(), out.bytes.begin());
    }
    return out;
}

asio::ip::address_v6 group(const char* text, unsigned scope) {
    auto g = asio::ip::make_address_v6(text);
    g.scope_id(scope);
    return g;
}

bool is_link_local_host(const std::string& host) {
    if (host.find('%') != std::string::npos) return false;
    auto a = core::parse_ip_address(host);
    return a && a->is_link_local();
}

}  // namespace

std::string_view discovery_event_name(DiscoveryEvent::Kind k) noexcept {
    switch (k) {
        case DiscoveryEvent::Kind::node_added: return "node_added";
        case DiscoveryEvent::Kind::node_updated: return "node_updated";
        case DiscoveryEvent::Kind::node_lost: return "node_lost";
        case DiscoveryEvent::Kind::services_updated: return "services_updated";
    }
    return "?";
}

struct NodeDiscovery::Socket {
    explicit Socket(asio::any_io_executor ex) : socket(ex) {}
    udp::socket socket;
    std::array<char, core::kMaxDatagram + 1> buffer{};
    udp::endpoint from;
};

std::shared_ptr<NodeDiscovery> NodeDiscovery::create(asio::any_io_executor executor, DiscoveryOptions options) {
    return std::shared_ptr<NodeDiscovery>(new NodeDiscovery(std::move(executor), std::move(options)));
}

NodeDiscovery::NodeDiscovery(asio::any_io_executor executor, DiscoveryOptions options)
    : executor_(executor),
      strand_(asio::make_strand(executor)),
      options_(std::move(options)),
      timer_(strand_),
      table_(options_.limits),
      rng_(std::random_device{}()) {
    request_id_ = random_node_id();
    std::array<std::uint8_t, 16> r{};
    for (auto& b : r) b = static_cast<std::uint8_t>(rng_());
    nonce_ = core::make_service_state_nonce(r);
}

NodeDiscovery::~NodeDiscovery() = default;

std::uint32_t NodeDiscovery::random32() { return static_cast<std::uint32_t>(rng_()); }

Result<void> NodeDiscovery::start() {
    {
        std::lock_guard lock(mutex_);
        if (started_) return {};
        started_ = true;
        const auto t = now();
        if (options_.announce) announce_.start(t, options_.announce_period);
        if (options_.listen) requests_.trigger(t, random32());
    }
    // Sockets are opened synchronously so that a failure is reported to the caller.
    open_sockets();
    {
        std::lock_guard lock(mutex_);
        if (sockets_.empty()) return fail(MessageErrorType::IOError, "discovery: no UDP socket could be opened on port " +
                                                                         std::to_string(options_.port));
    }
    asio::post(strand_, [self = shared_from_this()] { self->arm_timer(); });
    return {};
}

void NodeDiscovery::stop(std::chrono::milliseconds wait) {
    const auto clients = stop_now();
    const auto until = std::chrono::steady_clock::now() + wait;
    while (std::chrono::steady_clock::now() < until) {
        {
            std::lock_guard lock(mutex_);
            if (running_interrogations_ == 0) break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    // close() only posts the disconnect: wait for the connections to end, so that a caller that then
    // stops its io threads leaves none behind (rr discover's exit leaked one under load).
    for (auto& [k, c] : clients) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now());
        if (left.count() <= 0) break;
        if (c) (void)std::static_pointer_cast<client::Client>(c)->close_wait(left);
    }
}

std::map<std::uint64_t, std::shared_ptr<void>> NodeDiscovery::stop_now() {
    std::vector<std::shared_ptr<Socket>> sockets;
    std::map<std::uint64_t, std::shared_ptr<void>> clients;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return {};
        stopped_ = true;
        sockets.swap(sockets_);
        listeners_.clear();
        clients.swap(interrogation_clients_);
    }
    for (auto& [k, c] : clients)
        if (c) std::static_pointer_cast<client::Client>(c)->close();
    asio::post(strand_, [self = shared_from_this(), sockets] {
        boost::system::error_code ec;
        for (auto& s : sockets) s->socket.close(ec);
        self->timer_.cancel();
    });
    return clients;
}

void NodeDiscovery::open_sockets() {
    const auto addrs = addresses();
    std::lock_guard lock(mutex_);
    boost::system::error_code ec;
    const auto flags = options_.flags;
    const bool v6_groups = flags & (core::kLinkLocal | core::kNodeLocal | core::kSiteLocal);
    std::shared_ptr<Socket> v6;
    for (const auto& s : sockets_)
        if (s->socket.local_endpoint(ec).address().is_v6()) v6 = s;
    if (!v6 && v6_groups) {
        auto s = std::make_shared<Socket>(strand_);
        s->socket.open(udp::v6(), ec);
        if (!ec) s->socket.set_option(udp::socket::reuse_address(true), ec);
        if (!ec) s->socket.set_option(asio::ip::v6_only(true), ec);
        if (!ec) s->socket.bind(udp::endpoint(asio::ip::address_v6::any(), options_.port), ec);
        if (!ec) {
            s->socket.set_option(asio::ip::multicast::enable_loopback(true), ec);
            s->socket.set_option(udp::socket::receive_buffer_size(1 << 18), ec);  // bursts of announces
            ec.clear();
            v6 = s;
            sockets_.push_back(s);
            receive(s);
        }
    }
    if (v6) {
        for (const auto& a : addrs) {
            if (!a.address.is_v6() || !a.up || !a.multicast) continue;
            const unsigned scope = a.if_index;
            if (std::find(joined_scopes_.begin(), joined_scopes_.end(), scope) != joined_scopes_.end()) continue;
            if (!a.address.to_v6().is_link_local() && !a.loopback) continue;
            boost::system::error_code jec;
            if (flags & core::kLinkLocal) v6->socket.set_option(asio::ip::multicast::join_group(asio::ip::make_address_v6("ff02::ba86"), scope), jec);
            if (flags & core::kNodeLocal) v6->socket.set_option(asio::ip::multicast::join_group(asio::ip::make_address_v6("ff01::ba86"), scope), jec);
            if (flags & core::kSiteLocal) v6->socket.set_option(asio::ip::multicast::join_group(asio::ip::make_address_v6("ff05::ba86"), scope), jec);
            joined_scopes_.push_back(scope);
        }
    }
    // IPv4 broadcasts are received whatever the flags, as the official node does (its IPv4 listening
    // socket opens regardless); kIpv4Broadcast decides only whether we send them (send_datagram).
    {
        bool have_v4 = false;
        for (const auto& s : sockets_) have_v4 |= s->socket.local_endpoint(ec).address().is_v4();
        if (!have_v4) {
            auto s = std::make_shared<Socket>(strand_);
            s->socket.open(udp::v4(), ec);
            if (!ec) s->socket.set_option(udp::socket::reuse_address(true), ec);
            if (!ec) s->socket.set_option(udp::socket::broadcast(true), ec);
            if (!ec) s->socket.bind(udp::endpoint(asio::ip::address_v4::any(), options_.port), ec);
            if (!ec) {
                sockets_.push_back(s);
                receive(s);
            }
        }
    }
    next_rescan_ = now() + kRescanPeriod;
}

void NodeDiscovery::receive(const std::shared_ptr<Socket>& s) {
    s->socket.async_receive_from(
        asio::buffer(s->buffer), s->from,
        asio::bind_executor(strand_, [self = shared_from_this(), s](boost::system::error_code ec, std::size_t n) {
            if (ec == asio::error::operation_aborted || !s->socket.is_open()) return;
            if (!ec) self->on_datagram(std::string_view(s->buffer.data(), n), s->from);
            self->receive(s);
        }));
}

void NodeDiscovery::on_datagram(std::string_view data, const udp::endpoint& from) {
    std::vector<DiscoveryEvent> events;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        const auto source = core::PacketSource{to_core(from.address())};
        auto r = core::parse_packet(data, source, options_.node_id, request_id_);
        if (auto* rej = std::get_if<core::Reject>(&r)) {
            table_.note_rejected(*rej);
            return;
        }
        auto& packet = std::get<core::Packet>(r);
        if (auto* req = std::get_if<core::Request>(&packet)) {
            (void)req;
            if (options_.announce) announce_.announce_soon(now());
        } else if (options_.listen) {
            auto& a = std::get<core::Announce>(packet);
            if (ignored(a.node_id)) return;
            if (from.address().is_v6() && from.address().to_v6().is_link_local()) {
                if (auto u = parse_connection_url(a.url); u && is_link_local_host(u->host)) {
                    if (zones_.size() < options_.limits.max_nodes * options_.limits.max_urls_per_node || zones_.count(u->host))
                        zones_[u->host] = from.address().to_v6().scope_id();
                }
            }
            NodeAnnouncement n{a.node_id, a.node_name, {a.url}, a.service_state_nonce, core::NodeSource::udp};
            auto res = table_.node_detected(n, now(), random32());
            for (auto& gone : table_.take_evicted()) events.push_back({DiscoveryEvent::Kind::node_lost, std::move(gone)});
            if (res == core::DetectResult::added || res == core::DetectResult::updated) {
                if (const auto* e = table_.find(a.node_id))
                    events.push_back({res == core::DetectResult::added ? DiscoveryEvent::Kind::node_added
                                                                         : DiscoveryEvent::Kind::node_updated,
                                      *e});
            }
        }
    }
    emit(std::move(events));
    arm_timer();
}

void NodeDiscovery::arm_timer() {
    std::optional<core::MonoTime> next;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        auto consider = [&](std::optional<core::MonoTime> t) {
            if (t && (!next || *t < *next)) next = t;
        };
        consider(table_.next_deadline());
        consider(refresh_deadline());
        consider(announce_.next_deadline());
        consider(requests_.next_deadline());
        consider(next_rescan_);
    }
    timer_.expires_at(*next);
    timer_.async_wait(asio::bind_executor(strand_, [self = shared_from_this()](boost::system::error_code ec) {
        if (ec == asio::error::operation_aborted) return;
        self->on_timer();
    }));
}

void NodeDiscovery::on_timer() {
    std::vector<DiscoveryEvent> events;
    bool announce = false, request = false, rescan = false;
    std::vector<NodeID> due;
    {
        std::lock_guard lock(mutex_);
        if (stopped_) return;
        const auto t = now();
        for (auto& lost : table_.expire(t)) events.push_back({DiscoveryEvent::Kind::node_lost, std::move(lost)});
        if (!events.empty()) {
            // Forget zones no node uses any more.
            std::set<std::string> hosts;
            for (const auto& [id, e] : table_.nodes())
                for (const auto& u : e.urls)
                    if (auto p = parse_connection_url(u.url)) hosts.insert(p->host);
            for (auto it = zones_.begin(); it != zones_.end();) it = hosts.count(it->first) ? std::next(it) : zones_.erase(it);
        }
        if (auto r = refresh_deadline(); r && *r <= t) {
            requests_.trigger(t, random32());
            last_refresh_ = t;
        }
        announce = announce_.due(t);
        request = requests_.due(t, random32());
        rescan = t >= next_rescan_;
        due = table_.take_due_updates(t);
    }
    if (rescan) open_sockets();
    if (announce) send_announces();
    if (request) send_requests();
    emit(std::move(events));
    start_interrogations(std::move(due));
    arm_timer();
}

void NodeDiscovery::send_datagram(const asio::ip::address& source, const std::string& text, bool ipv4_broadcast) {
    boost::system::error_code ec;
    udp::socket s(executor_);
    s.open(source.is_v4() ? udp::v4() : udp::v6(), ec);
    if (ec) return;
    s.set_option(udp::socket::reuse_address(true), ec);
    s.bind(udp::endpoint(source, options_.port), ec);
    if (ec) {
        ec.clear();
        s.bind(udp::endpoint(source, 0), ec);
        if (ec) return;
    }
    const auto flags = options_.flags;
    if (source.is_v4()) {
        if (!ipv4_broadcast) return;
        s.set_option(udp::socket::broadcast(true), ec);
        s.send_to(asio::buffer(text), udp::endpoint(asio::ip::address_v4::broadcast(), options_.port), 0, ec);
        return;
    }
    const auto v6 = source.to_v6();
    const unsigned scope = v6.scope_id();
    s.set_option(asio::ip::multicast::enable_loopback(true), ec);
    if (scope) s.set_option(asio::ip::multicast::outbound_interface(scope), ec);
    if (flags & core::kNodeLocal) s.send_to(asio::buffer(text), udp::endpoint(group("ff01::ba86", scope), options_.port), 0, ec);
    if (!v6.is_loopback()) {
        if (flags & core::kLinkLocal)
            s.send_to(asio::buffer(text), udp::endpoint(group("ff02::ba86", scope), options_.port), 0, ec);
        if (flags & core::kSiteLocal)
            s.send_to(asio::buffer(text), udp::endpoint(group("ff05::ba86", scope), options_.port), 0, ec);
    }
}

void NodeDiscovery::send_announces() {
    if (!options_.listen_endpoints || options_.node_id.is_any()) return;
    auto endpoints = options_.listen_endpoints();
    const auto local = addresses();
    std::set<std::pair<asio::ip::address, std::uint16_t>> targets;
    for (const auto& ep : endpoints) {
        const auto a = ep.address();
        const bool any4 = a.is_v4() && a.to_v4().is_unspecified();
        const bool any6 = a.is_v6() && a.to_v6().is_unspecified();  // dual-stack: IPv4 too
        if (any4 || any6) {
            for (const auto& l : local) {
                if (!l.up) continue;
                if (l.address.is_v4() || any6) targets.emplace(l.address, ep.port());
            }
        } else {
            targets.emplace(a, ep.port());
        }
    }
    const std::string nonce = service_state_nonce();
    for (const auto& [addr, port] : targets) {
        if (addr.is_v6()) {
            const auto v6 = addr.to_v6();
            if (!v6.is_link_local() && !v6.is_loopback()) continue;
            if (v6.is_v4_mapped()) continue;
        } else if (!(options_.flags & core::kIpv4Broadcast)) {
            continue;
        }
        auto text = core::format_announce(options_.node_id, options_.node_name, "rr+tcp", to_core(addr), port, nonce);
        send_datagram(addr, text, (options_.flags & core::kIpv4Broadcast) != 0);
    }
}

void NodeDiscovery::send_requests() {
    const auto text = core::format_request(request_id_);
    std::set<asio::ip::address> sources;
    for (const auto& l : addresses()) {
        if (!l.up) continue;
        if (l.address.is_v6() && !l.address.to_v6().is_link_local() && !l.address.to_v6().is_loopback()) continue;
        sources.insert(l.address);
    }
    sources.insert(asio::ip::address_v4::loopback());
    for (const auto& a : sources) send_datagram(a, text, (options_.flags & core::kIpv4Broadcast) != 0);
}

void NodeDiscovery::send_requests_now() {
    {
        std::lock_guard lock(mutex_);
        if (stopped_ || !options_.listen) return;
        requests_.trigger(now(), random32());
    }
    asio::post(strand_, [self = shared_from_this()] { self->arm_timer(); });
}

void NodeDiscovery::services_changed() {
    {
        std::lock_guard lock(mutex_);
        if (!options_.service_state_nonce) {
            std::array<std::uint8_t, 16> r{};
            std::string n;
            do {
                for (auto& b : r) b = static_cast<std::uint8_t>(rng_());
                n = core::make_service_state_nonce(r);
            } while (n == nonce_);
            nonce_ = n;
        }
        announce_.announce_soon(now());
        if (stopped_ || !started_) return;
    }
    asio::post(strand_, [self = shared_from_this()] { self->arm_timer(); });
}

std::string NodeDiscovery::service_state_nonce() const {
    if (options_.service_state_nonce) return options_.service_state_nonce();
    std::lock_guard lock(mutex_);
    return nonce_;
}

void NodeDiscovery::want_services(bool want) {
    {
        std::lock_guard lock(mutex_);
        want_services_ += want ? 1 : -1;
        if (want_services_ < 0) want_services_ = 0;
        table_.set_want_services(want_services_ > 0, now());
        if (stopped_ || !started_) return;
    }
    asio::post(strand_, [self = shared_from_this()] { self->arm_timer(); });
}

void NodeDiscovery::refresh_services() {
    {
        std::lock_guard lock(mutex_);
        table_.refresh_all_services(now(), random32());
        if (stopped_ || !started_) return;
    }
    asio::post(strand_, [self = shared_from_this()] { self->arm_timer(); });
}

bool NodeDiscovery::ignored(const NodeID& id) const {
    return std::find(options_.ignored_nodes.begin(), options_.ignored_nodes.end(), id) != options_.ignored_nodes.end();
}

rr::discovery::DetectResult NodeDiscovery::add_node(const NodeAnnouncement& announcement) {
    if (ignored(announcement.node_id)) return core::DetectResult::ignored;
    std::vector<DiscoveryEvent> events;
    core::DetectResult res;
    {
        std::lock_guard lock(mutex_);
        res = table_.node_detected(announcement, now(), random32());
        for (auto& gone : table_.take_evicted()) events.push_back({DiscoveryEvent::Kind::node_lost, std::move(gone)});
        if (res == core::DetectResult::added || res == core::DetectResult::updated)
            if (const auto* e = table_.find(announcement.node_id))
                events.push_back({res == core::DetectResult::added ? DiscoveryEvent::Kind::node_added
                                                                     : DiscoveryEvent::Kind::node_updated,
                                  *e});
    }
    emit(std::move(events));
    if (started_) asio::post(strand_, [self = shared_from_this()] { self->arm_timer(); });
    return res;
}

void NodeDiscovery::remove_node(const NodeID& id) {
    std::vector<DiscoveryEvent> events;
    {
        std::lock_guard lock(mutex_);
        if (auto e = table_.remove(id)) events.push_back({DiscoveryEvent::Kind::node_lost, std::move(*e)});
    }
    emit(std::move(events));
}

void NodeDiscovery::remove_urls(const NodeID& id, const std::vector<std::string>& urls) {
    std::vector<DiscoveryEvent> events;
    {
        std::lock_guard lock(mutex_);
        std::optional<NodeEntry> lost;
        if (!table_.remove_urls(id, urls, lost)) return;
        if (lost) {
            events.push_back({DiscoveryEvent::Kind::node_lost, std::move(*lost)});
        } else if (const auto* e = table_.find(id)) {
            events.push_back({DiscoveryEvent::Kind::node_updated, *e});
        }
    }
    emit(std::move(events));
}

std::optional<core::MonoTime> NodeDiscovery::refresh_deadline() const {
    if (!options_.listen) return std::nullopt;
    auto oldest = table_.oldest_announce();
    if (!oldest) return std::nullopt;
    const auto expiry = options_.limits.url_expiry;
    return std::max(*oldest + expiry * 3 / 4, last_refresh_ + expiry / 4);
}

std::vector<LocalAddress> NodeDiscovery::addresses() const {
    auto all = local_addresses();
    if (options_.interfaces.empty()) return all;
    std::vector<LocalAddress> out;
    for (auto& a : all)
        if (std::find(options_.interfaces.begin(), options_.interfaces.end(), a.if_name) != options_.interfaces.end())
            out.push_back(std::move(a));
    return out;
}

std::uint16_t NodeDiscovery::bound_port() const {
    std::lock_guard lock(mutex_);
    boost::system::error_code ec;
    for (const auto& s : sockets_)
        if (auto ep = s->socket.local_endpoint(ec); !ec) return ep.port();
    return options_.port;
}

std::vector<NodeEntry> NodeDiscovery::nodes() const {
    std::lock_guard lock(mutex_);
    std::vector<NodeEntry> out;
    out.reserve(table_.size());
    for (const auto& [id, e] : table_.nodes()) out.push_back(e);
    return out;
}

std::optional<NodeEntry> NodeDiscovery::node(const NodeID& id) const {
    std::lock_guard lock(mutex_);
    if (const auto* e = table_.find(id)) return *e;
    return std::nullopt;
}

NodeTableCounters NodeDiscovery::counters() const {
    std::lock_guard lock(mutex_);
    return table_.counters();
}

std::size_t NodeDiscovery::size() const {
    std::lock_guard lock(mutex_);
    return table_.size();
}

std::size_t NodeDiscovery::interrogations() const {
    std::lock_guard lock(mutex_);
    return running_interrogations_;
}

std::vector<std::string> NodeDiscovery::connectable_urls(const std::string& url) const {
    auto u = parse_connection_url(url);
    if (!u || !is_link_local_host(u->host)) return {url};
    auto with_zone = [&](unsigned scope) {
        auto p = url.find("[" + u->host + "]");
        if (p == std::string::npos) return url;
        std::string out = url;
        out.insert(p + 1 + u->host.size(), "%" + std::to_string(scope));
        return out;
    };
    {
        std::lock_guard lock(mutex_);
        if (auto it = zones_.find(u->host); it != zones_.end()) return {with_zone(it->second)};
    }
    std::vector<std::string> out;
    std::set<unsigned> scopes;
    for (const auto& l : addresses())
        if (l.up && l.address.is_v6() && l.address.to_v6().is_link_local() && scopes.insert(l.if_index).second)
            out.push_back(with_zone(l.if_index));
    if (out.empty()) out.push_back(url);
    return out;
}

void NodeDiscovery::start_interrogations(std::vector<NodeID> due) {
    std::vector<std::pair<NodeID, std::pair<std::vector<std::string>, std::string>>> start;
    {
        std::lock_guard lock(mutex_);
        for (auto& id : due)
            if (std::find(waiting_interrogations_.begin(), waiting_interrogations_.end(), id) == waiting_interrogations_.end())
                waiting_interrogations_.push_back(id);
        if (waiting_interrogations_.size() > table_.size())  // evicted or lost nodes: bounded by the table
            std::erase_if(waiting_interrogations_, [&](const NodeID& id) { return table_.find(id) == nullptr; });
        while (running_interrogations_ < options_.max_parallel_interrogations && !waiting_interrogations_.empty()) {
            NodeID id = waiting_interrogations_.front();
            waiting_interrogations_.erase(waiting_interrogations_.begin());
            const auto* e = table_.find(id);
            if (!e) continue;
            std::vector<std::string> urls;
            for (const auto& u : e->urls) {
                const auto scheme = core::url_scheme(u.url);
                if (std::find(options_.interrogate_schemes.begin(), options_.interrogate_schemes.end(), scheme) ==
                    options_.interrogate_schemes.end())
                    continue;
                urls.push_back(u.url);
            }
            if (urls.empty()) {
                table_.services_failed(id, "no URL of a scheme to ask", now(), random32());
                continue;
            }
            ++running_interrogations_;
            start.push_back({id, {std::move(urls), e->service_state_nonce}});
        }
    }
    for (auto& [id, job] : start) {
        std::vector<std::string> expanded;
        for (const auto& u : job.first)
            for (auto& c : connectable_urls(u)) expanded.push_back(std::move(c));
        interrogate(id, std::move(expanded), 0, job.second);
    }
}

void NodeDiscovery::interrogate(NodeID id, std::vector<std::string> urls, std::size_t index, std::string nonce) {
    auto self = shared_from_this();
    auto finish = [self, id, nonce](Result<std::vector<ServiceInfo2>> r) {
        std::vector<DiscoveryEvent> events;
        {
            std::lock_guard lock(self->mutex_);
            if (self->running_interrogations_) --self->running_interrogations_;
            if (r) {
                if (self->table_.services_updated(id, nonce, std::move(*r), self->now()))
                    if (const auto* e = self->table_.find(id)) events.push_back({DiscoveryEvent::Kind::services_updated, *e});
            } else {
                self->table_.services_failed(id, r.error().message, self->now(), self->random32());
            }
        }
        self->emit(std::move(events));
        asio::post(self->strand_, [self] {
            self->start_interrogations({});
            self->arm_timer();
        });
    };
    {
        std::lock_guard lock(mutex_);
        if (stopped_) {
            if (running_interrogations_) --running_interrogations_;
            return;
        }
    }
    if (index >= urls.size()) return finish(fail(MessageErrorType::ConnectionError, "no URL answered"));
    client::ClientOptions opts;
    opts.connect_timeout = options_.interrogate_timeout;
    opts.request_timeout = options_.interrogate_timeout;
    opts.limits.max_message_size = 1u << 20;  // a service index reply is small (CORE drops > 64 KiB elements)
    opts.transports = options_.transports;
    // One bound for the whole attempt (transport, handshake, service index), so that each URL's try
    // ends by itself within interrogate_timeout.
    opts.total_connect_timeout = options_.interrogate_timeout;
    // The attempt is registered under `key` from the start, so that stop() can end it while it still
    // connects (a peer that accepts but never answers held rr discover's exit past stop's wait).
    std::uint64_t key = 0;
    {
        std::lock_guard lock(mutex_);
        key = next_interrogation_++;
        interrogation_clients_[key] = nullptr;  // filled in once start_connect returns
    }
    std::string url = urls[index];
    auto pending = client::Client::start_connect(
        executor_, url, opts,
        [self, id, urls, index, nonce, finish, key](Result<std::shared_ptr<client::Client>> c) mutable {
            if (!c) {
                {
                    std::lock_guard lock(self->mutex_);
                    self->interrogation_clients_.erase(key);
                }
                if (index + 1 < urls.size()) return self->interrogate(id, std::move(urls), index + 1, std::move(nonce));
                return finish(c.take_error());
            }
            auto client = *c;
            std::string name;
            {
                std::lock_guard lock(self->mutex_);
                if (self->stopped_) {
                    self->interrogation_clients_.erase(key);
                    if (self->running_interrogations_) --self->running_interrogations_;
                    client->close();
                    return;
                }
                if (const auto* e = self->table_.find(id)) name = e->node_name;
                self->interrogation_clients_[key] = client;
            }
            std::weak_ptr<client::Client> weak_client = client;
            client->root().async_call("GetLocalNodeServices", {},
                                      [self, weak_client, key, id, name, finish](Result<Value> v) {
                                          {
                                              std::lock_guard lock(self->mutex_);
                                              self->interrogation_clients_.erase(key);
                                          }
                                          if (auto cl = weak_client.lock()) cl->close();
                                          if (!v) return finish(v.take_error());
                                          finish(core::service_infos_from_value(*v, id, name,
                                                                                self->options_.limits.services));
                                      });
        });
    if (!pending) return;  // failed at once: the completion ran and dropped the key
    bool close_now = false;
    {
        std::lock_guard lock(mutex_);
        if (auto it = interrogation_clients_.find(key); it != interrogation_clients_.end()) {
            if (stopped_) {  // stopped between the registration and now: stop_now() did not see it
                interrogation_clients_.erase(it);
                close_now = true;
            } else if (!it->second) {
                it->second = pending;
            }
        } else {
            // Ended already (the key is gone), or stop() took the map before the client was known:
            // closing an ended client does nothing.
            close_now = stopped_;
        }
    }
    if (close_now) pending->close();
}

void NodeDiscovery::emit(std::vector<DiscoveryEvent> events) {
    if (events.empty()) return;
    std::vector<std::uint64_t> ids;
    {
        std::lock_guard lock(mutex_);
        for (const auto& [id, l] : listeners_) ids.push_back(id);
    }
    if (ids.empty()) return;
    // The listeners registered now, called only if still registered when the events are delivered: one
    // removed in between (remove_listener, stop) is not called, so its owner may go away once that
    // returned.
    asio::post(strand_, [self = shared_from_this(), events = std::move(events), ids = std::move(ids)] {
        std::vector<Listener> listeners;
        {
            std::lock_guard lock(self->mutex_);
            for (auto id : ids)
                if (auto it = self->listeners_.find(id); it != self->listeners_.end()) listeners.push_back(it->second);
        }
        for (const auto& e : events)
            for (const auto& l : listeners) l(e);
    });
}

std::uint64_t NodeDiscovery::add_listener(Listener listener) {
    std::lock_guard lock(mutex_);
    const auto id = next_listener_++;
    listeners_.emplace(id, std::move(listener));
    return id;
}

void NodeDiscovery::remove_listener(std::uint64_t id) {
    std::lock_guard lock(mutex_);
    listeners_.erase(id);
}

}  // namespace rr::server::discovery
