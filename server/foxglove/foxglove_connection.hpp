// One Foxglove WebSocket connection on the gateway (internal to server/foxglove; docs/foxglove.md).
// Its concerns live in one file each:
//   foxglove_connection.cpp      login, serverInfo, feeding the sans-IO session, advertise/unadvertise
//   foxglove_subscriptions.cpp   subscribe/unsubscribe: the upstream subscription or pipe per subscription
//   foxglove_values.cpp          messageData from the shared entries, backpressure, pipe/image conversion
//   foxglove_parameters.cpp      getParameters / setParameters / subscribeParameterUpdates on properties
//   foxglove_services.cpp        service calls on functions
//   foxglove_client_publish.cpp  clientAdvertise + client messageData to writable wires and pipes
//   foxglove_clock.cpp           (the server's) `time` from a device's clock; receive times
//
// Thread-safe: the socket's strand delivers messages, device strands deliver values and replies;
// mutex_ guards the protocol state and the subscriptions. Calls into devices are made without it.
#pragma once

#include <atomic>
#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>

#include "core/foxglove/foxglove_session.hpp"
#include "server/foxglove/foxglove_channels.hpp"
#include "server/foxglove/foxglove_clock.hpp"
#include "server/foxglove/foxglove_server.hpp"
#include "server/gateway/auth/http_auth.hpp"
#include "server/gateway/conversion_budget.hpp"
#include "server/gateway/session_endpoints.hpp"

namespace rr::server::foxglove {

namespace fg = rr::foxglove;

/// The gateway's wall clock in ns since the Unix epoch (messageData receive times).
std::uint64_t now_ns();
/// "<name>: <message>" of an API error, for status texts.
inline std::string error_text(const gateway::ApiError& e) { return e.name + ": " + e.message; }

class FoxgloveConnection : public std::enable_shared_from_this<FoxgloveConnection> {
public:
    FoxgloveConnection(std::weak_ptr<FoxgloveServer> server, std::shared_ptr<gateway::JsonApi> api,
                       std::shared_ptr<http::JsonSocket> socket, boost::asio::any_io_executor executor,
                       boost::asio::strand<boost::asio::any_io_executor> convert_strand, const FoxgloveOptions& options,
                       std::shared_ptr<FoxgloveClock> clock);

    /// Checks the path and the login, then sends serverInfo and the advertise of `server`'s catalog.
    void start();
    void on_text(std::string text);
    void on_binary(std::string bytes);
    /// The socket closed: subscriptions and client channels end, motion held by this client stops.
    void close();

    void advertise(const FoxgloveServer::Catalog& added);
    void unadvertise(const std::vector<std::uint32_t>& channel_ids, const std::vector<std::uint32_t>& service_ids);
    void parameter_changed(const rr::foxglove::Parameter& p);
    /// The followed clock has a new time: a `time` message of the clock's now_ns() when this connection
    /// has the capability (dropped while the socket is congested; the next one follows). Read under this
    /// connection's lock, so time messages and receive times reach the client in order.
    void time();
    FoxgloveStats stats() const;

private:
    using SharedEntryPtr = gateway::SharedEntryPtr;

    struct Sub {
        std::uint32_t id = 0;
        std::uint64_t serial = 0;  // this connection's count: a reused subscription id is another Sub
        std::shared_ptr<const LiveMember> member;
        std::uint64_t upstream = 0;
        bool upstream_known = false;
        bool active = false;      // the upstream subscription is open
        bool cancelled = false;   // ended before its upstream answered
        SharedEntryPtr pending;   // the newest wire value waiting while the socket is behind
        std::uint64_t newest_arrival = 0;  // a wire: the SharedEntry arrival of the newest value taken
    };

    struct PublishTarget {
        std::shared_ptr<const LiveMember> member;
        std::uint64_t serial = 0;
        std::uint64_t upstream = 0;  // a wire: the DeviceMirror subscription that keeps it connected; a pipe: the endpoint
        bool upstream_known = false;
        bool ready = false;                   // that wire connection / pipe endpoint is open
        std::optional<MessageEntry> pending;  // a wire: the newest value published before it was
        std::deque<MessageElement> pending_packets;  // a pipe: packets not yet sent, in order
        bool sending = false;                        // a pipe: one caller sends pending_packets (in order)
    };

    // --- connection (foxglove_connection.cpp) ---
    void refuse(const std::string& why);
    // Under mutex_.
    void status(const std::string& message, rr::foxglove::StatusLevel level = rr::foxglove::StatusLevel::error);
    void advertise_locked(const FoxgloveServer::Catalog& c);
    gateway::MemberAddress address_of(const LiveMember& m) const;
    std::shared_ptr<const gateway::MotionClient> motion_client() const;
    void act(rr::foxglove::Output out, std::unique_lock<std::mutex>& lock);
    /// A messageData receive time: the followed clock's when this connection has `time`, else the wall clock.
    std::uint64_t receive_ns() const;

    // --- subscriptions (foxglove_subscriptions.cpp) ---
    void on(rr::foxglove::event::Subscribed e);
    void on(rr::foxglove::event::Unsubscribed e);
    /// Opens a pipe endpoint of the gateway's shared session on `member`; `done` gets its id, or why not
    /// (an endpoint that opens after this connection is gone is closed).
    void open_pipe(const std::shared_ptr<const LiveMember>& member, gateway::GatewayPipeHandlers handlers,
                   std::function<void(FoxgloveConnection&, std::optional<std::uint64_t>, const std::string&)> done);
    void start_upstream(std::uint32_t sid, std::uint64_t serial, const std::shared_ptr<const LiveMember>& member);
    void open_upstream(std::uint32_t sid, std::uint64_t serial, const std::shared_ptr<const LiveMember>& member);
    void upstream_opened(std::uint32_t sid, std::uint64_t serial, const std::shared_ptr<const LiveMember>& member,
                         std::optional<std::uint64_t> id, const std::string& error);
    void upstream_closed(std::uint32_t sid, std::uint64_t serial, const std::string& why);
    void end_upstream(Sub& s);

    // --- values (foxglove_values.cpp) ---
    /// Under mutex_: the subscription `sid` while it is the one of `serial` and the connection is open.
    Sub* live_sub(std::uint32_t sid, std::uint64_t serial);
    /// Under mutex_: live_sub, unless the socket is congested for events and pipe packets (one more dropped).
    Sub* push_sub(std::uint32_t sid, std::uint64_t serial);
    bool wire_congested() const;
    bool push_congested() const;
    void send_entry(const Sub& s, const SharedEntryPtr& e);
    void on_wire(std::uint32_t sid, std::uint64_t serial, const SharedEntryPtr& e);
    void on_event(std::uint32_t sid, std::uint64_t serial, const SharedEntryPtr& e);
    bool take_newer(Sub& s, const gateway::SharedEntry& e);
    bool image_subscription(std::uint32_t sid) const;
    void arm_retry();
    void flush_locked();
    void on_pipe_packet(std::uint32_t sid, std::uint64_t serial, const MessageElement& packet);
    void convert(std::uint32_t sid, std::uint64_t serial, SharedEntryPtr entry);

    // --- parameters (foxglove_parameters.cpp) ---
    void on(rr::foxglove::event::GetParameters e);
    void on(rr::foxglove::event::SetParameters e);
    void on(rr::foxglove::event::ParametersSubscribed e);
    bool begin_parameter_request();
    void read_parameters(std::vector<std::shared_ptr<const LiveMember>> members,
                         std::function<void(std::vector<rr::foxglove::Parameter>)> done);
    std::vector<std::shared_ptr<const LiveMember>> properties_named(const std::vector<std::string>& names,
                                                                    std::vector<std::string>& unknown) const;
    void report_unknown(const std::vector<std::string>& unknown, const char* op);

    // --- services (foxglove_services.cpp) ---
    void on(rr::foxglove::event::ServiceCall e);

    // --- client publish (foxglove_client_publish.cpp) ---
    void on(rr::foxglove::event::ClientAdvertised e);
    void on(rr::foxglove::event::ClientUnadvertised e);
    void on(rr::foxglove::event::ClientPublish e);
    void publish_opened(std::uint32_t cid, std::uint64_t serial, const std::shared_ptr<const LiveMember>& member,
                        std::optional<std::uint64_t> pipe, const std::string& error);
    void publish_closed(std::uint32_t cid, std::uint64_t serial, const std::string& why);
    void end_publish(PublishTarget& p);
    void send_upstream(const LiveMember& member, MessageEntry entry);
    void send_pipe_packets(std::uint32_t cid, std::uint64_t serial);

    static std::uint64_t next_id();

    std::weak_ptr<FoxgloveServer> server_;
    std::shared_ptr<gateway::JsonApi> api_;
    std::shared_ptr<http::JsonSocket> socket_;
    const FoxgloveOptions options_;
    mutable std::mutex mutex_;
    rr::foxglove::Session session_;
    boost::asio::steady_timer timer_;
    bool started_ = false, closed_ = false, timer_armed_ = false;
    std::map<std::uint32_t, Sub> subs_;
    std::map<std::uint32_t, PublishTarget> publish_targets_;  // by client channel id
    std::set<std::uint32_t> publish_refused_;                 // client channels whose refusal was reported
    std::size_t parameter_requests_ = 0;
    std::uint64_t next_serial_ = 0;
    gateway::auth::PrincipalPtr principal_;
    FoxgloveStats stats_;
    const std::string motion_key_ = "foxglove:" + std::to_string(next_id());
    boost::asio::strand<boost::asio::any_io_executor> convert_strand_;
    gateway::ConversionBudget pipe_budget_;
    std::shared_ptr<FoxgloveClock> clock_;
    std::atomic<bool> sends_time_{false};  // serverInfo had the `time` capability
};

}  // namespace rr::server::foxglove
