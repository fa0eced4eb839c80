// The native typed client (namespace rr::client; the service side's object model is rr::server): connects to a service by URL, runs core's ClientContext on a strand, and
// offers every member kind by name through object proxies (ObjectProxy) and handles (PipeEndpoint,
// WireConnection, Generator).
//
// Two layers:
//   * asynchronous: `async_*` functions and Client::run(); completions and handlers run on the
//     connection's strand (no thread hand-off: the strand sends the request and runs the reply handler);
//   * blocking: the plain functions wait for the answer (at most the request timeout plus a margin) and
//     return Result<T>. They must not be called from the strand (a handler), which would deadlock; they
//     return InvalidOperation there.
//
// Transports are pluggable by URL scheme (ClientOptions::transports, server/transport/transport_registry.hpp);
// `rr+tcp` (and the legacy `tcp`)
// and `rr+ws` / `rr+wss` (server/transport/websocket_connector.hpp) are built in.
//
// Thread-safety: every public function may be called from any thread. Handlers must not block.
// Lifetime: handlers that capture a Client or ObjectProxy keep the connection alive until close().
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/strand.hpp>

#include "base/names/connection_url.hpp"
#include "core/session/client_context.hpp"
#include "server/client/caller_io.hpp"
#include "server/common/caller_runs_executor.hpp"
#include "server/transport/connection_logic.hpp"
#include "server/transport/stream_pump.hpp"
#include "server/transport/transport_registry.hpp"

namespace rr::client {

using server::ConnectionLogic;
using server::PumpHandle;

struct ClientOptions {
    NodeID local_node_id;  ///< all-zero: random
    std::string local_node_name;
    std::string username, password;
    /// A gateway's bearer token or JWT (docs/security.md "Native RR clients"): sent as the credentials
    /// {"token": token} instead of a password; `username` is then `<name>@token` or `<sub>@jwt`.
    std::string token;
    bool enable_message4 = true;
    bool enable_string_table = true;
    std::chrono::milliseconds connect_timeout{5000};      ///< TCP connect, with TLS/WebSocket handshakes (wire.md §13)
    /// Bound on the whole connect: transport (connect_timeout applies too), CreateConnection and the
    /// service connect exchange; ConnectionError "connect timed out after S s: …" beyond it.
    /// 0 = only the per-step timeouts (connect_timeout, 10 s for CreateConnection, request_timeout).
    std::chrono::milliseconds total_connect_timeout{0};
    std::chrono::milliseconds request_timeout{15000};     ///< per request, and the client session connect
    std::chrono::milliseconds heartbeat_period{10000};    ///< ConnectionTest when idle (wire.md §6.3)
    std::chrono::milliseconds receive_timeout{15000};     ///< close when nothing arrives for this long
    std::uint32_t memory_max_transfer_size = 102400;      ///< bytes per memory transfer
    /// rr+wss, rrs+tcp: PEM file of the certificates to trust ("" = the system's); the server's
    /// certificate must also name the URL's host (rrs+tcp: or the node, server/transport/tls/rrs_connector.hpp).
    std::string tls_ca_file;
    /// TLS: own certificate chain and key (PEM) for servers that require client certificates (mTLS).
    std::string tls_certificate_file, tls_private_key_file;
    /// rr+ws/rr+wss: the WebSocket handshake's Authorization header ("" = none), for a reverse proxy's
    /// login (see server::basic_authorization() in server/transport/websocket_connector.hpp). Not the RR login above.
    std::string http_authorization;
    Limits limits;
    /// Connectors by URL scheme (nullptr: server::default_transports(), the built-in ones).
    const server::TransportRegistry* transports = nullptr;
    /// The calling thread runs the connection's I/O while it waits: for a program whose io_context
    /// no other thread runs (IoThreads(0)) and that calls from one thread. A blocking call then
    /// sleeps once per reply, in the socket wait itself, instead of a worker thread waking for the
    /// reply and then waking the caller (issue 14: one context switch per call, not two); alone, it
    /// sleeps there without a timeout (server/client/caller_io.hpp: a timeout re-armed per call cost
    /// more CPU than the call), bounded by request_timeout. Events, wire values, callbacks and
    /// heartbeats are handled only while a blocking call, close_wait() or poll() runs: call poll() at
    /// least every heartbeat_period when idle. Other threads calling at the same time still complete,
    /// up to 1 ms later. A thread of the program's own that runs the io_context (io_context::run)
    /// would leave a caller asleep: use IoThreads(0), or no caller_runs_io.
    bool caller_runs_io = false;
};

/// The connection's strand: a blocking call runs its own request on it when it is idle
/// (server/common/caller_runs_executor.hpp), so the reply is the call's only wake-up.
using ClientStrand = boost::asio::strand<server::CallerRunsExecutor>;

/// The transport options of `options` (server/transport/transport.hpp).
server::ConnectOptions connect_options(const ClientOptions& options);

/// An io_context with worker threads, for programs that have no executor of their own. With 0
/// threads nothing runs it: for clients with ClientOptions::caller_runs_io.
class IoThreads {
public:
    explicit IoThreads(unsigned threads = 1);
    ~IoThreads();
    IoThreads(const IoThreads&) = delete;
    IoThreads& operator=(const IoThreads&) = delete;
    boost::asio::any_io_executor executor() { return io_.get_executor(); }

private:
    boost::asio::io_context io_;
    boost::asio::executor_work_guard<boost::asio::io_context::executor_type> work_;
    std::vector<std::thread> threads_;
};

class ObjectProxy;

class Client : public std::enable_shared_from_this<Client> {
public:
    using ConnectHandler = std::function<void(Result<std::shared_ptr<Client>>)>;

    /// Connects to `url` (must name a service) and establishes the client session; `done` runs on the
    /// connection's strand (or at once for a bad URL / unknown scheme). `executor` is an io_context's
    /// executor or a strand of one (InvalidArgument otherwise): the connection gets its own strand of
    /// that io_context.
    static void connect(boost::asio::any_io_executor executor, std::string_view url, ClientOptions options,
                        ConnectHandler done);
    /// connect(), returning the client while it connects (nullptr when `done` already ran with an
    /// error), so that the caller can abandon the attempt: close() or close_wait() on it ends the
    /// connect (`done` then gets an error) and the connection.
    static std::shared_ptr<Client> start_connect(boost::asio::any_io_executor executor, std::string_view url,
                                                 ClientOptions options, ConnectHandler done);
    /// Blocking connect. Errors: those of the transport and of the connect exchange.
    static Result<std::shared_ptr<Client>> connect(boost::asio::any_io_executor executor, std::string_view url,
                                                   ClientOptions options = {});

    ~Client();
    Client(const Client&) = delete;
    Client& operator=(const Client&) = delete;

    /// Proxy of the root object.
    ObjectProxy root();
    /// Proxy of a known object (from ObjectProxy::objref).
    ObjectProxy object(ObjectRef ref);

    const ClientSessionInfo& info() const noexcept { return info_; }
    const NodeID& remote_node_id() const noexcept { return remote_node_id_; }
    bool is_open() const noexcept { return open_.load(); }
    /// Called on the strand once the established session ends.
    void set_closed_handler(std::function<void(const RRError&)> handler);
    /// DisconnectClient, then close; returns at once.
    void close();
    /// close(), then waits (up to `timeout`) until the connection is closed, or, for a client still
    /// connecting (start_connect), until the attempt has ended. Not on the strand.
    Result<void> close_wait(std::chrono::milliseconds timeout = std::chrono::milliseconds(5000));
    /// With ClientOptions::caller_runs_io: runs the connection's pending I/O, events and timers on this
    /// thread for `duration`. Otherwise (worker threads do that) it only waits. Not on the strand.
    void poll(std::chrono::milliseconds duration);

    /// Runs `fn` on the strand (inline when already there) with the context and the current time.
    /// Not run at all when the connection is already gone.
    void run(std::function<void(ClientContext&, MonoTime)> fn);
    /// Starts an operation on the strand and waits for its completion (blocking layer).
    /// Errors: InvalidOperation on the strand, RequestTimeout after request timeout + 5 s,
    /// ConnectionError when the connection is gone.
    template <class T>
    Result<T> wait(std::function<void(ClientContext&, MonoTime, Completion<T>)> start);
    /// Runs `fn` on the strand and waits for its result (for non-network context calls).
    template <class T>
    Result<T> query(std::function<Result<T>(ClientContext&, MonoTime)> fn);
    /// True on a thread currently running the strand.
    bool on_strand() const noexcept { return strand_ && strand_->running_in_this_thread(); }

    class Logic;

private:
    Client() = default;
    friend class Logic;

    std::shared_ptr<Logic> logic_;
    std::shared_ptr<PumpHandle> current_pump() const;
    std::weak_ptr<PumpHandle> pump_;        // written once on the strand, before pump_set_
    std::atomic<bool> pump_set_{false};
    std::optional<ClientStrand> strand_;
    ClientSessionInfo info_;
    ObjectRef root_;
    NodeID remote_node_id_;
    std::atomic<bool> open_{false};
    std::atomic<bool> close_requested_{false};  // close() before the connection had its pump
    std::atomic<bool> connecting_{true};        // until the connect handler has run
    bool caller_runs_io_ = false;
    /// caller_runs_io: a lone caller waits for its answer without a timeout (caller_io.hpp), which
    /// needs the request timeout to bound the wait.
    bool untimed_waits_ = false;
    /// caller_runs_io: the io_context's runners, looked up once (not per call).
    detail::CallerIoRunners* io_runners_ = nullptr;
    std::chrono::milliseconds wait_limit_{20000};
    std::shared_ptr<std::promise<void>> closed_promise_ = std::make_shared<std::promise<void>>();
    std::shared_future<void> closed_future_ = closed_promise_->get_future().share();
};

/// The wall clock as a wire time stamp.
TimeSpec wall_clock_now();

/// A generator (wire.md §6.7).
class Generator {
public:
    Generator() = default;
    /// Next value; error StopIteration at the end. `parameter` for generators with a generator parameter.
    Result<Value> next(std::optional<Value> parameter = std::nullopt);
    void async_next(std::optional<Value> parameter, Completion<Value> done);
    /// Calls next() until StopIteration; returns every value.
    Result<std::vector<Value>> next_all();
    Result<void> close();
    Result<void> abort();
    explicit operator bool() const noexcept { return client_ && handle_; }

private:
    friend class ObjectProxy;
    Generator(std::shared_ptr<Client> c, GeneratorHandle h) : client_(std::move(c)), handle_(h) {}
    std::shared_ptr<Client> client_;
    GeneratorHandle handle_;
};

/// A connected pipe endpoint. Received packets are queued here (receive()) unless a packet handler
/// is set. Destroying the last copy does not close the endpoint: call close().
class PipeEndpoint {
public:
    PipeEndpoint() = default;
    const PipeEndpointInfo& info() const noexcept { return info_; }
    std::int32_t index() const noexcept { return info_.index; }
    /// Sends a packet; returns its packet number once it is queued for sending.
    Result<std::uint32_t> send(Value packet);
    void async_send(Value packet, Completion<std::uint32_t> done);
    Result<void> set_request_ack(bool request_ack);
    /// Waits up to `timeout` for the next packet. Errors: OperationTimeout, ConnectionError (closed, none left).
    Result<Value> receive(std::chrono::milliseconds timeout);
    std::optional<Value> try_receive();
    std::size_t available() const;
    /// Packet numbers acknowledged by the service so far.
    std::vector<std::uint32_t> acks() const;
    /// Waits until at least `n` acks arrived. Errors: OperationTimeout.
    Result<void> wait_acks(std::size_t n, std::chrono::milliseconds timeout) const;
    bool is_closed() const;
    /// Waits until the service closed the endpoint. Errors: OperationTimeout.
    Result<void> wait_closed(std::chrono::milliseconds timeout) const;
    /// Handlers on the strand: every packet (instead of queueing), and the close.
    void set_packet_handler(std::function<void(Value&&)> handler);
    void set_closed_handler(std::function<void(const RRError&)> handler);
    Result<void> close();
    explicit operator bool() const noexcept { return client_ && state_; }

    struct State;

private:
    friend class ObjectProxy;
    std::shared_ptr<Client> client_;
    std::shared_ptr<State> state_;
    PipeEndpointInfo info_;
};

/// A connected wire connection.
class WireConnection {
public:
    WireConnection() = default;
    const WireConnectionInfo& info() const noexcept { return info_; }
    /// InValue (lifespan applied). Errors as ClientContext::wire_in_value.
    Result<WireValue> in_value() const;
    Result<WireValue> out_value() const;
    Result<void> set_out_value(Value value);
    Result<void> set_lifespans(std::int32_t in_ms, std::int32_t out_ms);
    /// Waits up to `timeout` for an InValue that satisfies `pred`, among the values numbered above
    /// `after` (values are numbered 1, 2, … as they arrive; values_received() is the current number;
    /// the last 256 are kept). Default: only values that arrive after this call.
    /// Errors: OperationTimeout, ConnectionError (closed).
    Result<WireValue> wait_value(std::function<bool(const WireValue&)> pred, std::chrono::milliseconds timeout,
                                 std::optional<std::uint64_t> after = std::nullopt) const;
    /// Number of InValues received so far (a value that came with the connect counts).
    std::uint64_t values_received() const;
    /// Handlers on the strand.
    void set_value_handler(std::function<void(const WireValue&)> handler);
    void set_closed_handler(std::function<void(const RRError&)> handler);
    bool is_closed() const;
    Result<void> wait_closed(std::chrono::milliseconds timeout) const;
    Result<void> close();
    explicit operator bool() const noexcept { return client_ && state_; }

    struct State;

private:
    friend class ObjectProxy;
    std::shared_ptr<Client> client_;
    std::shared_ptr<State> state_;
    WireConnectionInfo info_;
};

/// An object of the service, addressed by its service path; members by name.
class ObjectProxy {
public:
    ObjectProxy() = default;
    ObjectProxy(std::shared_ptr<Client> client, ObjectRef ref) : client_(std::move(client)), ref_(std::move(ref)) {}
    const ObjectRef& ref() const noexcept { return ref_; }
    const std::string& path() const noexcept { return ref_.path; }
    const std::string& type() const noexcept { return ref_.type; }
    Client& client() const { return *client_; }
    explicit operator bool() const noexcept { return client_ != nullptr; }

    // blocking
    Result<Value> get(std::string_view member) const;
    Result<void> set(std::string_view member, Value value) const;
    Result<Value> call(std::string_view member, std::vector<Value> args = {}) const;
    Result<Generator> generator(std::string_view member, std::vector<Value> args = {}) const;
    Result<ObjectProxy> objref(std::string_view member, ObjRefIndex index = {}) const;
    Result<std::uint64_t> subscribe(std::string_view member, EventHandler handler) const;
    void unsubscribe(std::uint64_t subscription) const;
    Result<void> set_callback(std::string_view member, CallbackHandler handler) const;
    Result<PipeEndpoint> pipe_connect(std::string_view member, std::int32_t index = -1) const;
    Result<WireConnection> wire_connect(std::string_view member) const;
    Result<WireValue> peek_in_value(std::string_view member) const;
    Result<WireValue> peek_out_value(std::string_view member) const;
    Result<void> poke_out_value(std::string_view member, Value value) const;
    Result<std::uint64_t> memory_length(std::string_view member) const;
    Result<std::uint64_t> memory_dim_count(std::string_view member) const;
    Result<std::vector<std::uint64_t>> memory_dimensions(std::string_view member) const;
    Result<Value> memory_read(std::string_view member, std::uint64_t pos, std::uint64_t count) const;
    Result<void> memory_write(std::string_view member, std::uint64_t pos, Value data) const;
    Result<Value> memory_read(std::string_view member, std::vector<std::uint64_t> pos,
                              std::vector<std::uint64_t> count) const;
    Result<void> memory_write(std::string_view member, std::vector<std::uint64_t> pos, Value data) const;
    Result<void> monitor_enter(std::int32_t timeout_ms) const;
    Result<void> monitor_exit() const;

    // asynchronous (completions on the strand)
    void async_get(std::string_view member, Completion<Value> done) const;
    void async_set(std::string_view member, Value value, Completion<void> done) const;
    void async_call(std::string_view member, std::vector<Value> args, Completion<Value> done) const;
    void async_objref(std::string_view member, ObjRefIndex index, Completion<ObjectProxy> done) const;
    void async_peek_in_value(std::string_view member, Completion<WireValue> done) const;
    void async_memory_read(std::string_view member, std::uint64_t pos, std::uint64_t count, Completion<Value> done) const;

private:
    std::shared_ptr<Client> client_;
    ObjectRef ref_;
};

// --- Client::wait / query ----------------------------------------------------------------------

namespace detail {
/// The result of a blocking call, waited for by the caller (one allocation; std::promise takes two).
template <class T>
class SyncWaiter {
public:
    /// The first result counts; later ones are ignored.
    void set(Result<T> r) {
        {
            std::lock_guard lock(mutex_);
            if (result_) return;
            result_.emplace(std::move(r));
            answered_.store(true);  // sequentially consistent: paired with UntimedWait (caller_io.hpp)
        }
        ready_.notify_one();
        untimed_wait.kick();
    }
    bool answered() const noexcept { return answered_.load(); }
    /// The result, or nullopt when none came within `limit`.
    std::optional<Result<T>> wait_for(std::chrono::steady_clock::duration limit) {
        std::unique_lock lock(mutex_);
        if (!ready_.wait_for(lock, limit, [this] { return result_.has_value(); })) return std::nullopt;
        return std::move(result_);
    }
    std::atomic<int> completions{0};  // live SyncCompletion copies
    UntimedWait untimed_wait;         // the waiting thread's, when it runs the io_context (caller_runs_io)

private:
    std::mutex mutex_;
    std::condition_variable ready_;
    std::optional<Result<T>> result_;
    std::atomic<bool> answered_{false};
};

/// The completion a blocking call hands to the strand. When its last copy is dropped unanswered
/// (the connection closed first), the call fails with ConnectionError.
template <class T>
class SyncCompletion {
public:
    explicit SyncCompletion(std::shared_ptr<SyncWaiter<T>> waiter) : waiter_(std::move(waiter)) { ++waiter_->completions; }
    SyncCompletion(const SyncCompletion& other) : waiter_(other.waiter_) { ++waiter_->completions; }
    SyncCompletion(SyncCompletion&& other) noexcept : waiter_(std::move(other.waiter_)) {}
    SyncCompletion& operator=(const SyncCompletion&) = delete;
    SyncCompletion& operator=(SyncCompletion&&) = delete;
    ~SyncCompletion() {
        if (waiter_ && --waiter_->completions == 0 && !waiter_->answered())
            waiter_->set(fail(MessageErrorType::ConnectionError, "client connection closed"));
    }
    void operator()(Result<T> r) const { waiter_->set(std::move(r)); }

private:
    std::shared_ptr<SyncWaiter<T>> waiter_;
};
}  // namespace detail

template <class T>
Result<T> Client::wait(std::function<void(ClientContext&, MonoTime, Completion<T>)> start) {
    if (on_strand()) return fail(MessageErrorType::InvalidOperation, "blocking client call on the client's strand");
    auto waiter = std::make_shared<detail::SyncWaiter<T>>();
    {
        server::CallerRunsExecutor::Scope caller_runs;
        run([done = detail::SyncCompletion<T>(waiter), start = std::move(start)](ClientContext& ctx, MonoTime now) {
            start(ctx, now, done);
        });
    }
    if (caller_runs_io_) {
        detail::run_io_until(*io_runners_, [&] { return waiter->answered(); }, std::chrono::steady_clock::now() + wait_limit_,
                             untimed_waits_ ? &waiter->untimed_wait : nullptr);
    }
    auto r = waiter->wait_for(caller_runs_io_ ? std::chrono::steady_clock::duration::zero()
                                              : std::chrono::steady_clock::duration(wait_limit_));
    if (!r) return fail(MessageErrorType::RequestTimeout, "no answer from the client connection in time");
    return std::move(*r);
}

template <class T>
Result<T> Client::query(std::function<Result<T>(ClientContext&, MonoTime)> fn) {
    return wait<T>([fn = std::move(fn)](ClientContext& ctx, MonoTime now, Completion<T> done) { done(fn(ctx, now)); });
}

}  // namespace rr::client
