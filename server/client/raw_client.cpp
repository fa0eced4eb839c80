#include "server/client/raw_client.hpp"

#include <boost/asio/strand.hpp>

#include "base/message/error_entry.hpp"
#include "core/session/request_map.hpp"
#include "server/common/connection_strand.hpp"
#include "server/common/random_ids.hpp"
#include "server/transport/completion_guard.hpp"

namespace rr::server {

namespace asio = boost::asio;

MessageElement token_credentials(const std::string& token) {
    MessageElement credentials;
    credentials.name = "credentials";
    credentials.type = DataTypes::dictionary_t;
    credentials.elements.push_back(make_string_element("token", token));
    return credentials;
}

/// The strand-side half: owns the ClientSession and routes its events.
class RawClient::Logic : public ConnectionLogic {
public:
    Logic(ClientSessionConfig config, MonoTime now) : session_(std::move(config), now) {}

    void on_bytes(std::span<const std::byte> bytes, MonoTime now) override {
        (void)session_.feed(bytes, now);
        dispatch();
    }
    bool has_output() const override { return session_.pending_output_size() != 0; }
    std::span<std::byte> read_space() override { return session_.read_space(); }
    void take_output(GatherBuffer& out) override {
        session_.take_output(out);
        if (auto c = client_.lock()) c->queued_.store(session_.pending_output_size());
    }
    std::optional<MonoTime> next_deadline() const override { return session_.next_deadline(); }
    void on_timer(MonoTime now) override {
        session_.on_timer(now);
        dispatch();
    }
    bool wants_close() const override { return session_.is_closed(); }
    void on_transport_closed(RRError error) override {
        fail_queued();
        session_.on_transport_closed(std::move(error));
        dispatch();
    }
    void on_wake() override {
        {
            std::lock_guard lock(queue_mutex_);
            outbox_taken_.swap(outbox_);
            wake_pending_ = false;
        }
        for (auto& q : outbox_taken_) {
            if (q.is_request)
                request(std::move(q.entry), q.timeout.count() < 0 ? request_timeout_ : q.timeout, std::move(q.done));
            else
                send(std::move(q.entry));
        }
        outbox_taken_.clear();  // keeps its capacity: no allocation per wake
    }

    ~Logic() override {
        fail_queued();
        run_close_waiters();
    }

    /// From any thread: `entry` goes out on the strand, after what was queued before it, with one wake
    /// of the pump for all that waits (no closure per entry). A request queued once the transport has
    /// closed gets ConnectionError at once.
    void queue(PumpHandle& pump, MessageEntry&& entry, bool is_request, std::chrono::milliseconds timeout, ReplyHandler done) {
        bool wake = false;
        {
            std::lock_guard lock(queue_mutex_);
            if (!closed_) {
                outbox_.emplace_back(std::move(entry), is_request, timeout, std::move(done));
                wake = !std::exchange(wake_pending_, true);
                done = nullptr;
            }
        }
        if (wake) pump.wake();
        if (is_request && done) done(fail(MessageErrorType::ConnectionError, "client connection closed"));
    }

    void request(MessageEntry&& entry, std::chrono::milliseconds timeout, ReplyHandler done) {
        auto id = session_.request(std::move(entry), mono_now(), timeout);
        if (!id) {
            done(id.take_error());
            return;
        }
        replies_.put(*id, std::move(done));
        if (auto c = client_.lock()) c->queued_.store(session_.pending_output_size());
    }
    void send(MessageEntry&& entry) {
        (void)session_.send_packet(std::move(entry), mono_now());
        if (auto c = client_.lock()) c->queued_.store(session_.pending_output_size());
    }
    void close(std::function<void()> closed) {
        if (closed) close_waiters_.push_back(std::move(closed));
        session_.disconnect(mono_now());
        dispatch();
        if (session_.is_closed()) run_close_waiters();  // ended before: no ClientSessionClosed comes
    }

    std::weak_ptr<RawClient> client_;
    std::shared_ptr<RawClient> connecting_;  // held until the connect completes
    ConnectHandler on_connect_;
    IncomingHandler on_incoming_;
    ClosedHandler on_closed_;
    std::chrono::milliseconds request_timeout_{15000};

private:
    struct Queued {
        Queued(MessageEntry&& e, bool request, std::chrono::milliseconds t, ReplyHandler d)
            : entry(std::move(e)), is_request(request), timeout(t), done(std::move(d)) {}
        MessageEntry entry;
        bool is_request = false;
        std::chrono::milliseconds timeout{-1};  // < 0: the client's default
        ReplyHandler done;                      // requests only
    };

    // What the transport's end leaves queued (its wake is dropped once the pump has closed) is
    // answered ConnectionError, and nothing is queued after it.
    void fail_queued() {
        std::vector<Queued> left;
        {
            std::lock_guard lock(queue_mutex_);
            closed_ = true;
            left.swap(outbox_);
        }
        for (auto& q : left)
            if (q.is_request && q.done) q.done(fail(MessageErrorType::ConnectionError, "client connection closed"));
    }

    void dispatch() {
        while (auto ev = session_.poll_event()) {
            if (auto* c = std::get_if<ClientSessionConnected>(&*ev)) {
                auto client = std::move(connecting_);
                if (!client) continue;
                client->info_ = c->info;
                client->remote_node_id_ = session_.stream().negotiated().remote_node_id;
                client->remote_node_name_ = session_.stream().negotiated().remote_node_name;
                client->open_.store(true);
                if (auto h = std::move(on_connect_)) h(std::move(client));
            } else if (auto* r = std::get_if<ClientResponse>(&*ev)) {
                auto it = replies_.find(r->request_id);
                if (it == replies_.end()) continue;
                auto done = replies_.take(it);
                done(std::move(r->entry));
            } else if (auto* in = std::get_if<ClientIncoming>(&*ev)) {
                if (on_incoming_) on_incoming_(std::move(in->entry));
            } else if (auto* closed = std::get_if<ClientSessionClosed>(&*ev)) {
                for (auto& [id, done] : replies_) done(fail(make_error(MessageErrorType::ConnectionError, closed->error.message)));
                replies_.clear();
                if (auto h = std::move(on_connect_)) {
                    connecting_.reset();
                    h(fail(closed->error));  // the connect itself failed
                    continue;
                }
                if (auto c = client_.lock()) c->open_.store(false);
                if (auto h = std::move(on_closed_)) h(closed->error);
                run_close_waiters();
            }
        }
    }

    void run_close_waiters() {
        auto waiters = std::move(close_waiters_);
        close_waiters_.clear();
        for (auto& w : waiters) w();
    }

    ClientSession session_;
    RequestMap<ReplyHandler> replies_;
    std::vector<std::function<void()>> close_waiters_;  // close()'s `closed`, run when the session ends
    std::mutex queue_mutex_;
    std::vector<Queued> outbox_;        // guarded by queue_mutex_
    bool wake_pending_ = false;         // guarded by queue_mutex_: a wake is on its way for outbox_
    bool closed_ = false;               // guarded by queue_mutex_: the transport has closed
    std::vector<Queued> outbox_taken_;  // on_wake's, kept for its capacity
};

void RawClient::connect(asio::any_io_executor executor, const ConnectionUrl& url, RawClientOptions options,
                        IncomingHandler incoming, ClosedHandler closed, ConnectHandler done) {
    const TransportRegistry& transports = options.transports ? *options.transports : default_transports();
    if (!transports.find(url.scheme)) {
        done(fail(MessageErrorType::ConnectionError, "no transport for \"" + url.scheme + "\" URLs"));
        return;
    }
    if (url.service.empty()) {
        done(fail(MessageErrorType::InvalidArgument, "URL names no service: " + url.to_string()));
        return;
    }
    ClientSessionConfig cfg;
    cfg.stream.local_node_id = options.local_node_id.is_any() ? server::random_node_id() : options.local_node_id;
    cfg.stream.local_node_name = options.local_node_name;
    cfg.stream.target_node_id = url.node_id;
    cfg.stream.target_node_name = url.node_name;
    cfg.stream.enable_message4 = options.enable_message4;
    cfg.stream.enable_string_table = options.enable_string_table;
    cfg.stream.limits = options.limits;
    cfg.service_name = url.service;
    cfg.username = options.username;
    cfg.password = options.password;
    cfg.credentials = options.credentials;
    cfg.request_timeout = options.request_timeout;
    cfg.local_endpoint = server::random_endpoint_id();

    std::shared_ptr<RawClient> client(new RawClient());
    auto logic = std::make_shared<Logic>(std::move(cfg), mono_now());
    logic->client_ = client;
    logic->connecting_ = client;
    logic->on_connect_ = std::move(done);
    logic->on_incoming_ = std::move(incoming);
    logic->on_closed_ = std::move(closed);
    logic->request_timeout_ = options.request_timeout;
    client->logic_ = logic;
    ConnectOptions connect;
    connect.connect_timeout = options.connect_timeout;
    connect.tls_ca_file = options.tls_ca_file;
    connect.tls_certificate_file = options.tls_certificate_file;
    connect.tls_private_key_file = options.tls_private_key_file;
    connect.http_authorization = options.http_authorization;
    asio::any_io_executor strand = connection_strand(executor);
    transports.connect(strand, url, connect, logic, [logic](Result<std::shared_ptr<PumpHandle>> pump) {
        if (!pump) {
            // Never connected: the session reports the error to the connect handler (and drops it).
            logic->on_transport_closed(pump.error());
            return;
        }
        if (auto c = logic->client_.lock()) c->pump_ = *pump;
    });
}

void RawClient::request(MessageEntry entry, ReplyHandler done) {
    queue_request(std::move(entry), std::chrono::milliseconds(-1), std::move(done));
}

void RawClient::request(MessageEntry entry, std::chrono::milliseconds timeout, ReplyHandler done) {
    queue_request(std::move(entry), timeout, std::move(done));
}

void RawClient::queue_request(MessageEntry&& entry, std::chrono::milliseconds timeout, ReplyHandler&& done) {
    auto pump = pump_.lock();
    if (!pump || !open_.load()) {
        done(fail(MessageErrorType::ConnectionError, "client connection closed"));
        return;
    }
    logic_->queue(*pump, std::move(entry), /*is_request=*/true, timeout, std::move(done));
}

void RawClient::send(MessageEntry entry) {
    auto pump = pump_.lock();
    if (!pump) return;
    logic_->queue(*pump, std::move(entry), /*is_request=*/false, {}, nullptr);
}

RawClient::~RawClient() { close(); }

void RawClient::close(std::function<void()> closed) {
    auto pump = pump_.lock();
    if (!pump) {
        if (closed) closed();
        return;
    }
    if (!closed) {
        pump->dispatch([logic = logic_] { logic->close(nullptr); });
        return;
    }
    // The guard calls `closed` if the pump drops this work unrun (it has closed meanwhile).
    auto guard = std::make_shared<CompletionGuard<void>>([closed = std::move(closed)](Result<void>) { closed(); });
    pump->dispatch([logic = logic_, guard] {
        logic->close([done = guard->take()] { done({}); });
    });
}

}  // namespace rr::server
