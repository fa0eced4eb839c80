#include "server/client/raw_client.hpp"

#include <boost/asio/strand.hpp>

#include "core/session/request_map.hpp"
#include "server/common/connection_strand.hpp"
#include "server/common/random_ids.hpp"
#include "server/transport/completion_guard.hpp"

namespace rr::server {

namespace asio = boost::asio;

/// The strand-side half: owns the ClientSession and routes its events.
class RawClient::Logic : public ConnectionLogic {
public:
    Logic(ClientSessionConfig config, MonoTime now) : session_(std::move(config), now) {}

    void on_bytes(std::span<const std::byte> bytes, MonoTime now) override {
        (void)session_.feed(bytes, now);
        dispatch();
    }
    bool has_output() const override { return session_.pending_output_size() != 0; }
    void take_output(std::vector<std::byte>& out) override {
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
        session_.on_transport_closed(std::move(error));
        dispatch();
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
    void close() {
        session_.disconnect(mono_now());
        dispatch();
    }

    std::weak_ptr<RawClient> client_;
    std::shared_ptr<RawClient> connecting_;  // held until the connect completes
    ConnectHandler on_connect_;
    IncomingHandler on_incoming_;
    ClosedHandler on_closed_;
    std::chrono::milliseconds request_timeout_{15000};

private:
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
            }
        }
    }

    ClientSession session_;
    RequestMap<ReplyHandler> replies_;
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
    request(std::move(entry), std::chrono::milliseconds(-1), std::move(done));
}

void RawClient::request(MessageEntry entry, std::chrono::milliseconds timeout, ReplyHandler done) {
    auto pump = pump_.lock();
    if (!pump || !open_.load()) {
        done(fail(MessageErrorType::ConnectionError, "client connection closed"));
        return;
    }
    auto logic = logic_;
    auto guard = std::make_shared<CompletionGuard<MessageEntry>>(std::move(done));
    pump->dispatch([logic, entry = std::move(entry), timeout, guard]() mutable {
        auto t = timeout.count() < 0 ? logic->request_timeout_ : timeout;
        logic->request(std::move(entry), t, guard->take());
    });
}

void RawClient::send(MessageEntry entry) {
    auto pump = pump_.lock();
    if (!pump) return;
    auto logic = logic_;
    pump->dispatch([logic, entry = std::move(entry)]() mutable { logic->send(std::move(entry)); });
}

RawClient::~RawClient() { close(); }

void RawClient::close() {
    auto pump = pump_.lock();
    if (!pump) return;
    auto logic = logic_;
    pump->dispatch([logic] { logic->close(); });
}

}  // namespace rr::server
