// One Foxglove WebSocket connection's state (docs/foxglove.md), without I/O: which channels and
// services the server advertised to it, its subscriptions, client channels, parameter subscriptions
// and service calls in flight. The adapter (server/foxglove) feeds it the client's messages and acts
// on the events it returns; what is wrong with a message becomes one status message (level error)
// for the client and nothing else.
//
// Bounds (SessionLimits): subscriptions, client channels, parameter subscriptions and calls in flight
// per connection; a message over a bound is refused as a whole with a status naming the bound.
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "core/foxglove/foxglove_protocol.hpp"

namespace rr::foxglove {

struct SessionLimits {
    DecodeLimits decode;
    std::size_t max_subscriptions = 1024;
    std::size_t max_client_channels = 256;
    std::size_t max_parameter_subscriptions = 4096;
    std::size_t max_calls_in_flight = 32;
    /// Message encodings a client may publish and call services with (serverInfo.supportedEncodings).
    std::vector<std::string> encodings{"json"};
};

namespace event {
/// Start sending channel `channel_id`'s messages to the client as subscription `subscription_id`.
struct Subscribed {
    std::uint32_t subscription_id = 0, channel_id = 0;
};
/// Stop it (asked by the client).
struct Unsubscribed {
    std::uint32_t subscription_id = 0, channel_id = 0;
};
struct ClientAdvertised {
    ClientChannel channel;
};
struct ClientUnadvertised {
    ClientChannel channel;
};
/// A message on an advertised client channel; `payload` views the fed message.
struct ClientPublish {
    const ClientChannel* channel = nullptr;  ///< valid until the next feed
    std::string_view payload;
};
struct GetParameters {
    std::vector<std::string> names;
    std::optional<std::string> id;
};
struct SetParameters {
    std::vector<Parameter> parameters;
    std::optional<std::string> id;
};
/// The names now subscribed in addition ("all" when the client named none: `all` true).
struct ParametersSubscribed {
    std::vector<std::string> names;
    bool all = false;
};
/// A call of an advertised service; answer with call_finished() once its response or failure went out.
struct ServiceCall {
    std::uint32_t service_id = 0, call_id = 0;
    std::string encoding;
    std::string_view payload;
};
}  // namespace event

using Event = std::variant<event::Subscribed, event::Unsubscribed, event::ClientAdvertised, event::ClientUnadvertised,
                           event::ClientPublish, event::GetParameters, event::SetParameters, event::ParametersSubscribed,
                           event::ServiceCall>;

/// What one fed message produced: events for the adapter and text messages (statuses, a service call
/// failure) for the client, in that order of sending.
struct Output {
    std::vector<Event> events;
    std::vector<std::string> texts;
};

class Session {
public:
    explicit Session(SessionLimits limits = {}) : limits_(std::move(limits)) {}

    /// The client's text / binary message. Views of the input in the returned events stay valid while
    /// the input does.
    Output feed_text(std::string_view text);
    Output feed_binary(std::string_view bytes);

    // --- what the server advertises (the adapter tells the session what it sent) ---

    void channels_advertised(const std::vector<Channel>& channels);
    /// Channels gone: their subscriptions end (returned, for the adapter to stop sending).
    std::vector<event::Unsubscribed> channels_unadvertised(const std::vector<std::uint32_t>& channel_ids);
    void services_advertised(const std::vector<Service>& services);
    void services_unadvertised(const std::vector<std::uint32_t>& service_ids);
    /// The server ended subscription `subscription_id` itself (refused for rights, or its upstream
    /// failed): the id and its channel are free again.
    void end_subscription(std::uint32_t subscription_id);
    /// A call's response or failure was sent: it no longer counts against max_calls_in_flight.
    void call_finished(std::uint32_t service_id, std::uint32_t call_id);

    // --- queries ---

    bool channel_advertised(std::uint32_t channel_id) const { return channels_.count(channel_id) != 0; }
    /// The channel a subscription is on, or nothing.
    std::optional<std::uint32_t> subscription_channel(std::uint32_t subscription_id) const;
    /// Whether updates of parameter `name` go to the client.
    bool parameter_subscribed(const std::string& name) const { return all_parameters_ || parameters_.count(name) != 0; }
    std::size_t subscription_count() const noexcept { return subscriptions_.size(); }
    std::size_t client_channel_count() const noexcept { return client_channels_.size(); }
    std::size_t calls_in_flight() const noexcept { return calls_.size(); }
    const std::map<std::uint32_t, ClientChannel>& client_channels() const noexcept { return client_channels_; }
    const SessionLimits& limits() const noexcept { return limits_; }

private:
    void on(const Subscribe& m, Output& out);
    void on(const Unsubscribe& m, Output& out);
    void on(ClientAdvertise m, Output& out);
    void on(const ClientUnadvertise& m, Output& out);
    void on(GetParameters m, Output& out);
    void on(SetParameters m, Output& out);
    void on(SubscribeParameterUpdates m, Output& out);
    void on(const UnsubscribeParameterUpdates& m, Output& out);
    void on(const SubscribeConnectionGraph&, Output& out);
    void on(const UnsubscribeConnectionGraph&, Output& out);
    void on(const FetchAsset& m, Output& out);
    void on(const ClientMessageData& m, Output& out);
    void on(ServiceCallRequest m, Output& out);
    bool encoding_supported(const std::string& encoding) const;

    SessionLimits limits_;
    std::set<std::uint32_t> channels_;                           // advertised by the server
    std::set<std::uint32_t> services_;                           // advertised by the server
    std::map<std::uint32_t, std::uint32_t> subscriptions_;       // subscription id -> channel id
    std::map<std::uint32_t, std::uint32_t> channel_subscription_;  // channel id -> subscription id
    std::map<std::uint32_t, ClientChannel> client_channels_;     // by the client's channel id
    std::set<std::string> parameters_;                           // parameter subscriptions
    bool all_parameters_ = false;
    std::set<std::pair<std::uint32_t, std::uint32_t>> calls_;    // (service, call) in flight
};

}  // namespace rr::foxglove
