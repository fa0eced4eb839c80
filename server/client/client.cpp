#include "server/client/client.hpp"

#include <map>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/strand.hpp>

#include "base/message/error_entry.hpp"
#include "server/client/raw_client.hpp"
#include "server/common/random_ids.hpp"
#include "server/transport/completion_guard.hpp"

namespace rr::client {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using namespace std::chrono_literals;
using server::mono_now;
using server::StreamPump;

server::ConnectOptions connect_options(const ClientOptions& options) {
    server::ConnectOptions o;
    o.connect_timeout = options.connect_timeout;
    o.tls_ca_file = options.tls_ca_file;
    o.tls_certificate_file = options.tls_certificate_file;
    o.tls_private_key_file = options.tls_private_key_file;
    o.http_authorization = options.http_authorization;
    return o;
}

TimeSpec wall_clock_now() {
    auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    TimeSpec t;
    t.seconds = ns / 1'000'000'000;
    t.nanoseconds = static_cast<std::int32_t>(ns % 1'000'000'000);
    if (t.nanoseconds < 0) {
        t.nanoseconds += 1'000'000'000;
        --t.seconds;
    }
    return t;
}

// --- IoThreads -------------------------------------------------------------------------------------

IoThreads::IoThreads(unsigned threads) : work_(io_.get_executor()) {
    // Callers waiting with caller_runs_io must not sleep untimed while workers run the io_context too.
    detail::caller_io_runners(io_).workers.store(static_cast<int>(threads));
    for (unsigned i = 0; i < threads; ++i) threads_.emplace_back([this] { io_.run(); });
}

IoThreads::~IoThreads() {
    work_.reset();
    io_.stop();
    for (auto& t : threads_) t.join();
}

// --- Client ----------------------------------------------------------------------------------------

/// The strand-side half: owns the ClientContext.
class Client::Logic : public ConnectionLogic {
public:
    explicit Logic(ClientContextConfig config) : ctx(std::move(config), mono_now()) {}
    void on_bytes(std::span<const std::byte> bytes, MonoTime now) override { (void)ctx.feed(bytes, now); }
    bool has_output() const override { return ctx.pending_output_size() != 0; }
    void take_output(GatherBuffer& out) override { ctx.take_output(out); }
    std::span<std::byte> read_space() override { return ctx.read_space(); }
    std::optional<MonoTime> next_deadline() const override { return ctx.next_deadline(); }
    void on_timer(MonoTime now) override { ctx.on_timer(now); }
    bool wants_close() const override { return ctx.is_closed(); }
    void on_transport_closed(RRError error) override { ctx.on_transport_closed(std::move(error)); }
    // The connect handler holds the Client, which holds this logic: left set, neither would be freed.
    void on_abandoned() noexcept override {
        ctx.set_connect_handler({});
        user_closed = nullptr;
    }

    ClientContext ctx;
    std::function<void(const RRError&)> user_closed;  // strand only
};

namespace {

// The io_context executor under `executor` (itself, or the inner executor of a strand of it).
std::optional<asio::io_context::executor_type> io_context_executor(const asio::any_io_executor& executor) {
    if (const auto* io = executor.target<asio::io_context::executor_type>()) return *io;
    if (const auto* strand = executor.target<asio::strand<asio::io_context::executor_type>>())
        return strand->get_inner_executor();
    if (const auto* strand = executor.target<asio::strand<asio::any_io_executor>>()) {
        const asio::any_io_executor inner = strand->get_inner_executor();
        if (const auto* io = inner.target<asio::io_context::executor_type>()) return *io;
    }
    return std::nullopt;
}

}  // namespace

void Client::connect(asio::any_io_executor executor, std::string_view url_text, ClientOptions options,
                     ConnectHandler done) {
    (void)start_connect(std::move(executor), url_text, std::move(options), std::move(done));
}

std::shared_ptr<Client> Client::start_connect(asio::any_io_executor executor, std::string_view url_text,
                                              ClientOptions options, ConnectHandler done) {
    const auto failed = [&](Unexpected e) -> std::shared_ptr<Client> {
        done(std::move(e));
        return nullptr;
    };
    auto url = parse_connection_url(url_text);
    if (!url) return failed(url.take_error());
    if (url->service.empty())
        return failed(fail(MessageErrorType::InvalidArgument, "URL names no service: " + std::string(url_text)));
    const server::TransportRegistry& transports = options.transports ? *options.transports : server::default_transports();
    if (!transports.find(url->scheme))
        return failed(fail(MessageErrorType::ConnectionError, "no client transport for \"" + url->scheme + "\""));
    auto io = io_context_executor(executor);
    if (!io)
        return failed(fail(MessageErrorType::InvalidArgument,
                           "the client's executor is neither an io_context's executor nor a strand of one"));

    ClientContextConfig cfg;
    cfg.session.stream.local_node_id = options.local_node_id.is_any() ? server::random_node_id() : options.local_node_id;
    cfg.session.stream.local_node_name = options.local_node_name;
    cfg.session.stream.target_node_id = url->node_id;
    cfg.session.stream.target_node_name = url->node_name;
    cfg.session.stream.enable_message4 = options.enable_message4;
    cfg.session.stream.enable_string_table = options.enable_string_table;
    cfg.session.stream.heartbeat_period = options.heartbeat_period;
    cfg.session.stream.receive_timeout = options.receive_timeout;
    cfg.session.stream.limits = options.limits;
    cfg.session.service_name = url->service;
    cfg.session.username = options.username;
    cfg.session.password = options.password;
    if (!options.token.empty()) cfg.session.credentials = server::token_credentials(options.token);
    cfg.session.request_timeout = options.request_timeout;
    // One bound for the whole connect when asked for: the session counts it from here, before the
    // transport starts (its message then wins over the stream's own CreateConnection timeout).
    cfg.session.connect_timeout = options.total_connect_timeout;
    if (options.total_connect_timeout.count() > 0)
        cfg.session.stream.connect_timeout = std::max(cfg.session.stream.connect_timeout, options.total_connect_timeout);
    cfg.session.local_endpoint = server::random_endpoint_id();
    cfg.memory_max_transfer_size = options.memory_max_transfer_size;

    std::shared_ptr<Client> client(new Client());
    client->strand_.emplace(asio::make_strand(server::CallerRunsExecutor(*io)));
    client->caller_runs_io_ = options.caller_runs_io;
    client->untimed_waits_ = options.caller_runs_io && options.request_timeout.count() > 0;
    if (options.caller_runs_io) client->io_runners_ = &detail::caller_io_runners(io->context());
    client->wait_limit_ = options.request_timeout + 5s;
    auto logic = std::make_shared<Logic>(std::move(cfg));
    client->logic_ = logic;
    std::weak_ptr<Client> weak = client;
    Logic* lp = logic.get();
    // The connect handler holds the client until the connect completes (the context then drops it).
    logic->ctx.set_connect_handler([client, lp, done](Result<ObjectRef> r) mutable {
        auto c = std::move(client);
        c->connecting_.store(false);
        if (!r) return done(r.take_error());
        c->info_ = lp->ctx.info();
        c->root_ = *r;
        c->remote_node_id_ = lp->ctx.session().stream().negotiated().remote_node_id;
        c->open_.store(true);
        done(std::move(c));
    });
    logic->ctx.set_closed_handler([weak, lp](const RRError& e) {
        auto h = std::move(lp->user_closed);
        if (auto c = weak.lock()) {
            c->open_.store(false);
            c->closed_promise_->set_value();
        }
        if (h) h(e);
    });
    // Asio destroys a pending operation's handler uncalled when its io_context goes away first (a
    // program that exits while connecting): the context's connect handler, which holds the client,
    // which holds the logic, would then keep both alive for good. The last uncalled copy of the
    // transport's completion drops that handler (nothing else runs then: the io_context is gone).
    struct UncalledConnect {
        std::shared_ptr<Logic> logic;
        ~UncalledConnect() {
            if (logic) logic->on_abandoned();
        }
    };
    auto uncalled = std::make_shared<UncalledConnect>();
    uncalled->logic = logic;
    transports.connect(*client->strand_, *url, connect_options(options), logic,
              [client, logic, uncalled](Result<std::shared_ptr<PumpHandle>> pump) mutable {
                  uncalled->logic.reset();
                  if (!pump) {
                      auto h = std::move(client);
                      // Never connected: hand the error to the connect handler (and drop it).
                      ClientContext& ctx = logic->ctx;
                      ctx.on_transport_closed(pump.error());
                      return;
                  }
                  // pump_ is written once, here, then published; readers look only after pump_set_.
                  client->pump_ = *pump;
                  client->pump_set_.store(true);
                  // A close() that came while connecting found no pump to tell: disconnect now, or the
                  // connection would live on unowned. (Both stores and loads are sequentially
                  // consistent: a close() either sees pump_set_ or is seen here; a second disconnect
                  // does nothing.)
                  if (client->close_requested_.load())
                      (*pump)->dispatch([logic] { logic->ctx.disconnect(mono_now()); });
              });
    return client;
}

Result<std::shared_ptr<Client>> Client::connect(asio::any_io_executor executor, std::string_view url,
                                                ClientOptions options) {
    auto timeout = options.connect_timeout + options.request_timeout + 5s;
    auto waiter = std::make_shared<detail::SyncWaiter<std::shared_ptr<Client>>>();
    const bool caller_runs_io = options.caller_runs_io;
    connect(executor, url, std::move(options), detail::SyncCompletion<std::shared_ptr<Client>>(waiter));
    if (auto io = io_context_executor(executor); caller_runs_io && io) {
        detail::run_io_until(io->context(), [&] { return waiter->answered(); }, std::chrono::steady_clock::now() + timeout);
        timeout = {};
    }
    auto r = waiter->wait_for(timeout);
    if (!r) return fail(MessageErrorType::ConnectionError, "connect timed out");
    return std::move(*r);
}

Client::~Client() {
    if (auto pump = current_pump()) {
        auto logic = logic_;
        pump->dispatch([logic] { logic->ctx.disconnect(mono_now()); });
        if (caller_runs_io_ && !on_strand()) {
            // No worker thread writes the DisconnectClient: give it a moment on this one.
            std::weak_ptr<PumpHandle> weak = pump;
            pump.reset();
            detail::run_io_until(*io_runners_, [&] { return weak.expired(); },
                                 std::chrono::steady_clock::now() + std::chrono::milliseconds(200));
        }
    }
}

ObjectProxy Client::root() { return ObjectProxy(shared_from_this(), root_); }

ObjectProxy Client::object(ObjectRef ref) { return ObjectProxy(shared_from_this(), std::move(ref)); }

void Client::set_closed_handler(std::function<void(const RRError&)> handler) {
    run([handler = std::move(handler), logic = logic_](ClientContext&, MonoTime) mutable {
        logic->user_closed = std::move(handler);
    });
}

std::shared_ptr<PumpHandle> Client::current_pump() const {
    // No lock on the request path: pump_ does not change once published.
    if (!pump_set_.load()) return nullptr;
    return pump_.lock();
}

void Client::close() {
    close_requested_.store(true);
    run([](ClientContext& ctx, MonoTime now) { ctx.disconnect(now); });
}

Result<void> Client::close_wait(std::chrono::milliseconds timeout) {
    if (on_strand()) return fail(MessageErrorType::InvalidOperation, "blocking client call on the client's strand");
    close();
    const auto ended = [this] {
        return (!connecting_.load() && !open_.load()) ||
               closed_future_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
    };
    if (ended()) return {};
    const auto until = std::chrono::steady_clock::now() + timeout;
    if (caller_runs_io_) {
        detail::run_io_until(*io_runners_, ended, until);
    } else {
        // The closed future is set when an open connection closes; a failed connect only clears
        // connecting_, hence the short waits.
        while (!ended() && std::chrono::steady_clock::now() < until)
            (void)closed_future_.wait_for(std::chrono::milliseconds(10));
    }
    if (!ended()) return fail(MessageErrorType::OperationTimeout, "connection did not close in time");
    return {};
}

void Client::poll(std::chrono::milliseconds duration) {
    if (on_strand()) return;
    const auto until = std::chrono::steady_clock::now() + duration;
    if (caller_runs_io_) {
        detail::run_io_until(*io_runners_, [] { return false; }, until);
        return;
    }
    std::this_thread::sleep_until(until);
}

void Client::run(std::function<void(ClientContext&, MonoTime)> fn) {
    auto pump = current_pump();
    if (!pump) return;
    auto logic = logic_;
    pump->dispatch([logic, fn = std::move(fn)] { fn(logic->ctx, mono_now()); });
}

namespace {

Unexpected no_client() { return fail(MessageErrorType::InvalidOperation, "empty object proxy"); }

template <class T, class Start>
void async_op(Client& c, Completion<T> done, Start start) {
    auto guard = std::make_shared<server::CompletionGuard<T>>(std::move(done));
    c.run([guard, start = std::move(start)](ClientContext& ctx, MonoTime now) mutable {
        start(ctx, now, [guard](Result<T> r) { (*guard)(std::move(r)); });
    });
}

// is_closed()/wait_closed() of a pipe endpoint's or wire connection's shared state (mutex, cv, closed).
template <class State>
bool state_closed(const std::shared_ptr<State>& st) {
    if (!st) return true;
    std::lock_guard lock(st->mutex);
    return st->closed;
}

template <class State>
Result<void> wait_state_closed(const std::shared_ptr<State>& st, std::chrono::milliseconds timeout, const char* what) {
    if (!st) return {};
    std::unique_lock lock(st->mutex);
    if (!st->cv.wait_for(lock, timeout, [&] { return st->closed; }))
        return fail(MessageErrorType::OperationTimeout, std::string(what) + " not closed in time");
    return {};
}

}  // namespace

// --- Generator -------------------------------------------------------------------------------------

Result<Value> Generator::next(std::optional<Value> parameter) {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no generator");
    auto h = handle_;
    return client_->wait<Value>([h, parameter = std::move(parameter)](ClientContext& ctx, MonoTime now,
                                                                       Completion<Value> done) mutable {
        ctx.generator_next(h, std::move(parameter), now, std::move(done));
    });
}

void Generator::async_next(std::optional<Value> parameter, Completion<Value> done) {
    if (!client_) return done(fail(MessageErrorType::InvalidOperation, "no generator"));
    auto h = handle_;
    async_op<Value>(*client_, std::move(done), [h, parameter = std::move(parameter)](ClientContext& ctx, MonoTime now,
                                                                                      Completion<Value> d) mutable {
        ctx.generator_next(h, std::move(parameter), now, std::move(d));
    });
}

Result<std::vector<Value>> Generator::next_all() {
    std::vector<Value> out;
    for (;;) {
        auto v = next();
        if (!v) {
            if (v.error().type == MessageErrorType::StopIteration) return out;
            return v.take_error();
        }
        out.push_back(std::move(*v));
    }
}

Result<void> Generator::close() {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no generator");
    auto h = handle_;
    return client_->wait<void>(
        [h](ClientContext& ctx, MonoTime now, Completion<void> done) { ctx.generator_close(h, now, std::move(done)); });
}

Result<void> Generator::abort() {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no generator");
    auto h = handle_;
    return client_->wait<void>(
        [h](ClientContext& ctx, MonoTime now, Completion<void> done) { ctx.generator_abort(h, now, std::move(done)); });
}

// --- PipeEndpoint ----------------------------------------------------------------------------------

struct PipeEndpoint::State {
    mutable std::mutex mutex;
    mutable std::condition_variable cv;
    std::deque<Value> packets;
    std::vector<std::uint32_t> acks;
    bool closed = false;
    RRError close_error;
    PipeEndpointHandle handle;
    // strand only
    std::function<void(Value&&)> on_packet;
    std::function<void(const RRError&)> on_closed;
};

Result<std::uint32_t> PipeEndpoint::send(Value packet) {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no pipe endpoint");
    auto h = state_->handle;
    return client_->query<std::uint32_t>([h, packet = std::move(packet)](ClientContext& ctx, MonoTime now) {
        return ctx.pipe_send(h, packet, now);
    });
}

void PipeEndpoint::async_send(Value packet, Completion<std::uint32_t> done) {
    if (!client_) return done(fail(MessageErrorType::InvalidOperation, "no pipe endpoint"));
    auto h = state_->handle;
    async_op<std::uint32_t>(*client_, std::move(done), [h, packet = std::move(packet)](ClientContext& ctx, MonoTime now,
                                                                                        Completion<std::uint32_t> d) {
        d(ctx.pipe_send(h, packet, now));
    });
}

Result<void> PipeEndpoint::set_request_ack(bool request_ack) {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no pipe endpoint");
    auto h = state_->handle;
    return client_->query<void>([h, request_ack](ClientContext& ctx, MonoTime) { return ctx.set_pipe_request_ack(h, request_ack); });
}

Result<Value> PipeEndpoint::receive(std::chrono::milliseconds timeout) {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no pipe endpoint");
    if (client_->on_strand()) return fail(MessageErrorType::InvalidOperation, "blocking receive on the client's strand");
    std::unique_lock lock(state_->mutex);
    state_->cv.wait_for(lock, timeout, [&] { return !state_->packets.empty() || state_->closed; });
    if (!state_->packets.empty()) {
        Value v = std::move(state_->packets.front());
        state_->packets.pop_front();
        return v;
    }
    if (state_->closed) return fail(MessageErrorType::ConnectionError, "pipe endpoint closed: " + state_->close_error.message);
    return fail(MessageErrorType::OperationTimeout, "no pipe packet in time");
}

std::optional<Value> PipeEndpoint::try_receive() {
    if (!state_) return std::nullopt;
    std::lock_guard lock(state_->mutex);
    if (state_->packets.empty()) return std::nullopt;
    Value v = std::move(state_->packets.front());
    state_->packets.pop_front();
    return v;
}

std::size_t PipeEndpoint::available() const {
    if (!state_) return 0;
    std::lock_guard lock(state_->mutex);
    return state_->packets.size();
}

std::vector<std::uint32_t> PipeEndpoint::acks() const {
    if (!state_) return {};
    std::lock_guard lock(state_->mutex);
    return state_->acks;
}

Result<void> PipeEndpoint::wait_acks(std::size_t n, std::chrono::milliseconds timeout) const {
    if (!state_) return fail(MessageErrorType::InvalidOperation, "no pipe endpoint");
    std::unique_lock lock(state_->mutex);
    if (!state_->cv.wait_for(lock, timeout, [&] { return state_->acks.size() >= n; }))
        return fail(MessageErrorType::OperationTimeout, std::to_string(state_->acks.size()) + " of " + std::to_string(n) + " acks in time");
    return {};
}

bool PipeEndpoint::is_closed() const { return state_closed(state_); }

Result<void> PipeEndpoint::wait_closed(std::chrono::milliseconds timeout) const {
    return wait_state_closed(state_, timeout, "pipe endpoint");
}

void PipeEndpoint::set_packet_handler(std::function<void(Value&&)> handler) {
    if (!client_) return;
    client_->run([st = state_, handler = std::move(handler)](ClientContext&, MonoTime) mutable {
        st->on_packet = std::move(handler);
        if (!st->on_packet) return;
        std::deque<Value> queued;
        {
            std::lock_guard lock(st->mutex);
            queued.swap(st->packets);
        }
        for (auto& v : queued) st->on_packet(std::move(v));
    });
}

void PipeEndpoint::set_closed_handler(std::function<void(const RRError&)> handler) {
    if (!client_) return;
    client_->run([st = state_, handler = std::move(handler)](ClientContext&, MonoTime) mutable {
        st->on_closed = std::move(handler);
    });
}

Result<void> PipeEndpoint::close() {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no pipe endpoint");
    auto h = state_->handle;
    return client_->wait<void>(
        [h](ClientContext& ctx, MonoTime now, Completion<void> done) { ctx.pipe_close(h, now, std::move(done)); });
}

// --- WireConnection --------------------------------------------------------------------------------

struct WireConnection::State {
    static constexpr std::size_t kRecent = 256;
    mutable std::mutex mutex;
    mutable std::condition_variable cv;
    std::deque<std::shared_ptr<const WireValue>> recent;
    std::uint64_t seq = 0;  ///< values received so far
    bool closed = false;
    RRError close_error;
    WireConnectionHandle handle;
    // strand only
    std::function<void(const WireValue&)> on_value;
    std::function<void(const RRError&)> on_closed;
};

Result<WireValue> WireConnection::in_value() const {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no wire connection");
    auto h = state_->handle;
    return client_->query<WireValue>([h](ClientContext& ctx, MonoTime now) { return ctx.wire_in_value(h, now); });
}

Result<WireValue> WireConnection::out_value() const {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no wire connection");
    auto h = state_->handle;
    return client_->query<WireValue>([h](ClientContext& ctx, MonoTime now) { return ctx.wire_out_value(h, now); });
}

Result<void> WireConnection::set_out_value(Value value) {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no wire connection");
    auto h = state_->handle;
    return client_->query<void>([h, value = std::move(value)](ClientContext& ctx, MonoTime now) {
        return ctx.wire_set_out_value(h, value, wall_clock_now(), now);
    });
}

Result<void> WireConnection::set_lifespans(std::int32_t in_ms, std::int32_t out_ms) {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no wire connection");
    auto h = state_->handle;
    return client_->query<void>(
        [h, in_ms, out_ms](ClientContext& ctx, MonoTime) { return ctx.set_wire_lifespans(h, in_ms, out_ms); });
}

Result<WireValue> WireConnection::wait_value(std::function<bool(const WireValue&)> pred, std::chrono::milliseconds timeout,
                                             std::optional<std::uint64_t> after) const {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no wire connection");
    if (client_->on_strand()) return fail(MessageErrorType::InvalidOperation, "blocking wait on the client's strand");
    auto deadline = std::chrono::steady_clock::now() + timeout;
    std::unique_lock lock(state_->mutex);
    std::uint64_t checked = after ? std::min(*after, state_->seq) : state_->seq;  // values numbered 1..seq
    for (;;) {
        const std::uint64_t first = state_->seq - state_->recent.size() + 1;  // number of recent.front()
        for (std::uint64_t n = std::max(checked + 1, first); n <= state_->seq; ++n) {
            const auto& v = state_->recent[static_cast<std::size_t>(n - first)];
            if (pred(*v)) return *v;
        }
        checked = state_->seq;
        if (state_->closed) return fail(MessageErrorType::ConnectionError, "wire connection closed: " + state_->close_error.message);
        if (state_->cv.wait_until(lock, deadline) == std::cv_status::timeout && state_->seq == checked)
            return fail(MessageErrorType::OperationTimeout, "no matching wire value in time");
    }
}

std::uint64_t WireConnection::values_received() const {
    if (!state_) return 0;
    std::lock_guard lock(state_->mutex);
    return state_->seq;
}

void WireConnection::set_value_handler(std::function<void(const WireValue&)> handler) {
    if (!client_) return;
    client_->run([st = state_, handler = std::move(handler)](ClientContext&, MonoTime) mutable {
        st->on_value = std::move(handler);
    });
}

void WireConnection::set_closed_handler(std::function<void(const RRError&)> handler) {
    if (!client_) return;
    client_->run([st = state_, handler = std::move(handler)](ClientContext&, MonoTime) mutable {
        st->on_closed = std::move(handler);
    });
}

bool WireConnection::is_closed() const { return state_closed(state_); }

Result<void> WireConnection::wait_closed(std::chrono::milliseconds timeout) const {
    return wait_state_closed(state_, timeout, "wire connection");
}

Result<void> WireConnection::close() {
    if (!client_) return fail(MessageErrorType::InvalidOperation, "no wire connection");
    auto h = state_->handle;
    return client_->wait<void>(
        [h](ClientContext& ctx, MonoTime now, Completion<void> done) { ctx.wire_close(h, now, std::move(done)); });
}

// --- ObjectProxy -----------------------------------------------------------------------------------


Result<Value> ObjectProxy::get(std::string_view member) const {
    if (!client_) return no_client();
    return client_->wait<Value>([p = ref_.path, m = std::string(member)](ClientContext& ctx, MonoTime now, Completion<Value> done) {
        ctx.property_get(p, m, now, std::move(done));
    });
}

Result<void> ObjectProxy::set(std::string_view member, Value value) const {
    if (!client_) return no_client();
    return client_->wait<void>([p = ref_.path, m = std::string(member), value = std::move(value)](
                                   ClientContext& ctx, MonoTime now, Completion<void> done) mutable {
        ctx.property_set(p, m, std::move(value), now, std::move(done));
    });
}

Result<Value> ObjectProxy::call(std::string_view member, std::vector<Value> args) const {
    if (!client_) return no_client();
    return client_->wait<Value>([p = ref_.path, m = std::string(member), args = std::move(args)](
                                    ClientContext& ctx, MonoTime now, Completion<Value> done) mutable {
        ctx.call(p, m, std::move(args), now, std::move(done));
    });
}

Result<Generator> ObjectProxy::generator(std::string_view member, std::vector<Value> args) const {
    if (!client_) return no_client();
    auto h = client_->wait<GeneratorHandle>([p = ref_.path, m = std::string(member), args = std::move(args)](
                                                ClientContext& ctx, MonoTime now, Completion<GeneratorHandle> done) mutable {
        ctx.call_generator(p, m, std::move(args), now, std::move(done));
    });
    if (!h) return h.take_error();
    return Generator(client_, *h);
}

Result<ObjectProxy> ObjectProxy::objref(std::string_view member, ObjRefIndex index) const {
    if (!client_) return no_client();
    auto r = client_->wait<ObjectRef>([p = ref_.path, m = std::string(member), index = std::move(index)](
                                          ClientContext& ctx, MonoTime now, Completion<ObjectRef> done) mutable {
        ctx.objref(p, m, std::move(index), now, std::move(done));
    });
    if (!r) return r.take_error();
    return ObjectProxy(client_, std::move(*r));
}

Result<std::uint64_t> ObjectProxy::subscribe(std::string_view member, EventHandler handler) const {
    if (!client_) return no_client();
    return client_->query<std::uint64_t>([p = ref_.path, m = std::string(member), handler = std::move(handler)](
                                             ClientContext& ctx, MonoTime) { return ctx.subscribe_event(p, m, handler); });
}

void ObjectProxy::unsubscribe(std::uint64_t subscription) const {
    if (!client_) return;
    client_->run([subscription](ClientContext& ctx, MonoTime) { ctx.unsubscribe_event(subscription); });
}

Result<void> ObjectProxy::set_callback(std::string_view member, CallbackHandler handler) const {
    if (!client_) return no_client();
    return client_->query<void>([p = ref_.path, m = std::string(member), handler = std::move(handler)](
                                    ClientContext& ctx, MonoTime) { return ctx.set_callback(p, m, handler); });
}

Result<PipeEndpoint> ObjectProxy::pipe_connect(std::string_view member, std::int32_t index) const {
    if (!client_) return no_client();
    auto client = client_;
    return client_->wait<PipeEndpoint>([client, p = ref_.path, m = std::string(member), index](
                                           ClientContext& ctx, MonoTime now, Completion<PipeEndpoint> done) {
        ClientContext* cp = &ctx;
        ctx.pipe_connect(p, m, index, now, [client, cp, done = std::move(done)](Result<PipeEndpointHandle> h) {
            if (!h) return done(h.take_error());
            // On the strand, in the same turn as the connect: no packet can slip past the handlers.
            auto st = std::make_shared<PipeEndpoint::State>();
            st->handle = *h;
            std::weak_ptr<PipeEndpoint::State> weak = st;
            auto drain = [cp, weak](PipeEndpointHandle ep) {
                auto s = weak.lock();
                if (!s) return;
                while (auto v = cp->pipe_receive(ep)) {
                    if (s->on_packet) {
                        s->on_packet(std::move(*v));
                    } else {
                        std::lock_guard lock(s->mutex);
                        s->packets.push_back(std::move(*v));
                    }
                }
                s->cv.notify_all();
            };
            PipeEndpointHandlers handlers;
            handlers.packets = drain;
            handlers.ack = [weak](PipeEndpointHandle, std::uint32_t n) {
                auto s = weak.lock();
                if (!s) return;
                {
                    std::lock_guard lock(s->mutex);
                    s->acks.push_back(n);
                }
                s->cv.notify_all();
            };
            handlers.closed = [weak](PipeEndpointHandle, const RRError& e) {
                auto s = weak.lock();
                if (!s) return;
                {
                    std::lock_guard lock(s->mutex);
                    s->closed = true;
                    s->close_error = e;
                }
                s->cv.notify_all();
                if (auto f = s->on_closed) f(e);
            };
            (void)cp->set_pipe_handlers(*h, std::move(handlers));
            drain(*h);  // packets that came before the PipeConnectRet
            PipeEndpoint ep;
            ep.client_ = client;
            ep.state_ = std::move(st);
            ep.info_ = cp->pipe_info(*h).value();
            done(std::move(ep));
        });
    });
}

Result<WireConnection> ObjectProxy::wire_connect(std::string_view member) const {
    if (!client_) return no_client();
    auto client = client_;
    return client_->wait<WireConnection>([client, p = ref_.path, m = std::string(member)](
                                             ClientContext& ctx, MonoTime now, Completion<WireConnection> done) {
        ClientContext* cp = &ctx;
        ctx.wire_connect(p, m, now, [client, cp, done = std::move(done)](Result<WireConnectionHandle> h) {
            if (!h) return done(h.take_error());
            auto st = std::make_shared<WireConnection::State>();
            st->handle = *h;
            std::weak_ptr<WireConnection::State> weak = st;
            WireConnectionHandlers handlers;
            handlers.value = [weak](WireConnectionHandle, const WireValue& v) {
                auto s = weak.lock();
                if (!s) return;
                {
                    std::lock_guard lock(s->mutex);
                    s->recent.push_back(std::make_shared<const WireValue>(v));
                    if (s->recent.size() > WireConnection::State::kRecent) s->recent.pop_front();
                    ++s->seq;
                }
                s->cv.notify_all();
                if (auto f = s->on_value) f(v);
            };
            handlers.closed = [weak](WireConnectionHandle, const RRError& e) {
                auto s = weak.lock();
                if (!s) return;
                {
                    std::lock_guard lock(s->mutex);
                    s->closed = true;
                    s->close_error = e;
                }
                s->cv.notify_all();
                if (auto f = s->on_closed) f(e);
            };
            (void)cp->set_wire_handlers(*h, std::move(handlers));
            // A value that came before the WireConnectRet counts as received.
            if (auto v = cp->wire_in_value(*h, cp->now())) {
                std::lock_guard lock(st->mutex);
                st->recent.push_back(std::make_shared<const WireValue>(std::move(*v)));
                ++st->seq;
            }
            WireConnection wc;
            wc.client_ = client;
            wc.state_ = std::move(st);
            wc.info_ = cp->wire_info(*h).value();
            done(std::move(wc));
        });
    });
}

Result<WireValue> ObjectProxy::peek_in_value(std::string_view member) const {
    if (!client_) return no_client();
    return client_->wait<WireValue>([p = ref_.path, m = std::string(member)](ClientContext& ctx, MonoTime now,
                                                                             Completion<WireValue> done) {
        ctx.wire_peek_in_value(p, m, now, std::move(done));
    });
}

Result<WireValue> ObjectProxy::peek_out_value(std::string_view member) const {
    if (!client_) return no_client();
    return client_->wait<WireValue>([p = ref_.path, m = std::string(member)](ClientContext& ctx, MonoTime now,
                                                                             Completion<WireValue> done) {
        ctx.wire_peek_out_value(p, m, now, std::move(done));
    });
}

Result<void> ObjectProxy::poke_out_value(std::string_view member, Value value) const {
    if (!client_) return no_client();
    return client_->wait<void>([p = ref_.path, m = std::string(member), value = std::move(value)](
                                   ClientContext& ctx, MonoTime now, Completion<void> done) mutable {
        ctx.wire_poke_out_value(p, m, std::move(value), wall_clock_now(), now, std::move(done));
    });
}

Result<std::uint64_t> ObjectProxy::memory_length(std::string_view member) const {
    if (!client_) return no_client();
    return client_->wait<std::uint64_t>([p = ref_.path, m = std::string(member)](ClientContext& ctx, MonoTime now,
                                                                                 Completion<std::uint64_t> done) {
        ctx.memory_length(p, m, now, std::move(done));
    });
}

Result<std::uint64_t> ObjectProxy::memory_dim_count(std::string_view member) const {
    if (!client_) return no_client();
    return client_->wait<std::uint64_t>([p = ref_.path, m = std::string(member)](ClientContext& ctx, MonoTime now,
                                                                                 Completion<std::uint64_t> done) {
        ctx.memory_dim_count(p, m, now, std::move(done));
    });
}

Result<std::vector<std::uint64_t>> ObjectProxy::memory_dimensions(std::string_view member) const {
    if (!client_) return no_client();
    return client_->wait<std::vector<std::uint64_t>>(
        [p = ref_.path, m = std::string(member)](ClientContext& ctx, MonoTime now,
                                                 Completion<std::vector<std::uint64_t>> done) {
            ctx.memory_dimensions(p, m, now, std::move(done));
        });
}

Result<Value> ObjectProxy::memory_read(std::string_view member, std::uint64_t pos, std::uint64_t count) const {
    if (!client_) return no_client();
    return client_->wait<Value>([p = ref_.path, m = std::string(member), pos, count](ClientContext& ctx, MonoTime now,
                                                                                     Completion<Value> done) {
        ctx.memory_read(p, m, pos, count, now, std::move(done));
    });
}

Result<void> ObjectProxy::memory_write(std::string_view member, std::uint64_t pos, Value data) const {
    if (!client_) return no_client();
    return client_->wait<void>([p = ref_.path, m = std::string(member), pos, data = std::move(data)](
                                   ClientContext& ctx, MonoTime now, Completion<void> done) mutable {
        ctx.memory_write(p, m, pos, std::move(data), now, std::move(done));
    });
}

Result<Value> ObjectProxy::memory_read(std::string_view member, std::vector<std::uint64_t> pos,
                                       std::vector<std::uint64_t> count) const {
    if (!client_) return no_client();
    return client_->wait<Value>([p = ref_.path, m = std::string(member), pos = std::move(pos), count = std::move(count)](
                                    ClientContext& ctx, MonoTime now, Completion<Value> done) mutable {
        ctx.memory_read(p, m, std::move(pos), std::move(count), now, std::move(done));
    });
}

Result<void> ObjectProxy::memory_write(std::string_view member, std::vector<std::uint64_t> pos, Value data) const {
    if (!client_) return no_client();
    return client_->wait<void>([p = ref_.path, m = std::string(member), pos = std::move(pos), data = std::move(data)](
                                   ClientContext& ctx, MonoTime now, Completion<void> done) mutable {
        ctx.memory_write(p, m, std::move(pos), std::move(data), now, std::move(done));
    });
}

Result<void> ObjectProxy::monitor_enter(std::int32_t timeout_ms) const {
    if (!client_) return no_client();
    return client_->wait<void>([p = ref_.path, timeout_ms](ClientContext& ctx, MonoTime now, Completion<void> done) {
        ctx.monitor_enter(p, timeout_ms, now, std::move(done));
    });
}

Result<void> ObjectProxy::monitor_exit() const {
    if (!client_) return no_client();
    return client_->wait<void>(
        [p = ref_.path](ClientContext& ctx, MonoTime now, Completion<void> done) { ctx.monitor_exit(p, now, std::move(done)); });
}

void ObjectProxy::async_get(std::string_view member, Completion<Value> done) const {
    if (!client_) return done(no_client());
    async_op<Value>(*client_, std::move(done), [p = ref_.path, m = std::string(member)](ClientContext& ctx, MonoTime now,
                                                                                         Completion<Value> d) {
        ctx.property_get(p, m, now, std::move(d));
    });
}

void ObjectProxy::async_set(std::string_view member, Value value, Completion<void> done) const {
    if (!client_) return done(no_client());
    async_op<void>(*client_, std::move(done), [p = ref_.path, m = std::string(member), value = std::move(value)](
                                                  ClientContext& ctx, MonoTime now, Completion<void> d) mutable {
        ctx.property_set(p, m, std::move(value), now, std::move(d));
    });
}

void ObjectProxy::async_call(std::string_view member, std::vector<Value> args, Completion<Value> done) const {
    if (!client_) return done(no_client());
    async_op<Value>(*client_, std::move(done), [p = ref_.path, m = std::string(member), args = std::move(args)](
                                                   ClientContext& ctx, MonoTime now, Completion<Value> d) mutable {
        ctx.call(p, m, std::move(args), now, std::move(d));
    });
}

void ObjectProxy::async_objref(std::string_view member, ObjRefIndex index, Completion<ObjectProxy> done) const {
    if (!client_) return done(no_client());
    async_op<ObjectProxy>(*client_, std::move(done),
                          [client = client_, p = ref_.path, m = std::string(member), index = std::move(index)](
                              ClientContext& ctx, MonoTime now, Completion<ObjectProxy> d) mutable {
                              ctx.objref(p, m, std::move(index), now, [client, d = std::move(d)](Result<ObjectRef> r) {
                                  if (!r) return d(r.take_error());
                                  d(ObjectProxy(client, std::move(*r)));
                              });
                          });
}

void ObjectProxy::async_peek_in_value(std::string_view member, Completion<WireValue> done) const {
    if (!client_) return done(no_client());
    async_op<WireValue>(*client_, std::move(done), [p = ref_.path, m = std::string(member)](
                                                       ClientContext& ctx, MonoTime now, Completion<WireValue> d) {
        ctx.wire_peek_in_value(p, m, now, std::move(d));
    });
}

void ObjectProxy::async_memory_read(std::string_view member, std::uint64_t pos, std::uint64_t count,
                                    Completion<Value> done) const {
    if (!client_) return done(no_client());
    async_op<Value>(*client_, std::move(done), [p = ref_.path, m = std::string(member), pos, count](
                                                   ClientContext& ctx, MonoTime now, Completion<Value> d) {
        ctx.memory_read(p, m, pos, count, now, std::move(d));
    });
}

}  // namespace rr::client
