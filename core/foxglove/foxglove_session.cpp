#include "core/foxglove/foxglove_session.hpp"

#include <algorithm>

namespace rr::foxglove {
namespace {

std::string n(std::uint64_t v) { return std::to_string(v); }

void error_status(Output& out, std::string message) { out.texts.push_back(status_json(StatusLevel::error, message)); }

}  // namespace

Output Session::feed_text(std::string_view text) {
    Output out;
    auto m = decode_text(text, limits_.decode);
    if (!m) {
        error_status(out, "message refused: " + m.error().message);
        return out;
    }
    std::visit([&](auto&& msg) { on(std::move(msg), out); }, std::move(*m));
    return out;
}

Output Session::feed_binary(std::string_view bytes) {
    Output out;
    auto m = decode_binary(bytes, limits_.decode);
    if (!m) {
        error_status(out, "message refused: " + m.error().message);
        return out;
    }
    std::visit([&](auto&& msg) { on(std::move(msg), out); }, std::move(*m));
    return out;
}

void Session::on(const Subscribe& m, Output& out) {
    // Checked as a whole first: a refused message changes nothing.
    std::set<std::uint32_t> ids, channels;
    for (const auto& s : m.subscriptions) {
        if (!channels_.count(s.channel_id))
            return error_status(out, "subscribe refused: channel " + n(s.channel_id) + " is not advertised");
        if (subscriptions_.count(s.id) || !ids.insert(s.id).second)
            return error_status(out, "subscribe refused: subscription id " + n(s.id) + " is in use");
        if (channel_subscription_.count(s.channel_id) || !channels.insert(s.channel_id).second)
            return error_status(out, "subscribe refused: channel " + n(s.channel_id) + " is already subscribed on this connection");
    }
    if (subscriptions_.size() + m.subscriptions.size() > limits_.max_subscriptions)
        return error_status(out, "subscribe refused: more than " + n(limits_.max_subscriptions) + " subscriptions on this connection");
    for (const auto& s : m.subscriptions) {
        subscriptions_[s.id] = s.channel_id;
        channel_subscription_[s.channel_id] = s.id;
        out.events.push_back(event::Subscribed{s.id, s.channel_id});
    }
}

void Session::on(const Unsubscribe& m, Output& out) {
    std::vector<std::uint32_t> unknown;
    for (auto id : m.subscription_ids) {
        auto it = subscriptions_.find(id);
        if (it == subscriptions_.end()) {
            unknown.push_back(id);
            continue;
        }
        out.events.push_back(event::Unsubscribed{id, it->second});
        channel_subscription_.erase(it->second);
        subscriptions_.erase(it);
    }
    if (!unknown.empty()) {
        std::string list;
        for (auto id : unknown) list += (list.empty() ? "" : ", ") + n(id);
        error_status(out, "unsubscribe: no subscription " + list);
    }
}

bool Session::encoding_supported(const std::string& encoding) const {
    return std::find(limits_.encodings.begin(), limits_.encodings.end(), encoding) != limits_.encodings.end();
}

void Session::on(ClientAdvertise m, Output& out) {
    std::set<std::uint32_t> ids;
    for (const auto& c : m.channels) {
        if (client_channels_.count(c.id) || !ids.insert(c.id).second)
            return error_status(out, "advertise refused: client channel id " + n(c.id) + " is in use");
        if (!encoding_supported(c.encoding))
            return error_status(out, "advertise refused: channel \"" + c.topic + "\" has encoding \"" + c.encoding +
                                         "\"; this server takes json");
    }
    if (client_channels_.size() + m.channels.size() > limits_.max_client_channels)
        return error_status(out, "advertise refused: more than " + n(limits_.max_client_channels) + " client channels on this connection");
    for (auto& c : m.channels) {
        client_channels_[c.id] = c;
        out.events.push_back(event::ClientAdvertised{std::move(c)});
    }
}

void Session::on(const ClientUnadvertise& m, Output& out) {
    for (auto id : m.channel_ids) {
        auto it = client_channels_.find(id);
        if (it == client_channels_.end()) {
            error_status(out, "unadvertise: no client channel " + n(id));
            continue;
        }
        out.events.push_back(event::ClientUnadvertised{std::move(it->second)});
        client_channels_.erase(it);
    }
}

void Session::on(GetParameters m, Output& out) { out.events.push_back(event::GetParameters{std::move(m.names), std::move(m.id)}); }

void Session::on(SetParameters m, Output& out) {
    out.events.push_back(event::SetParameters{std::move(m.parameters), std::move(m.id)});
}

void Session::on(SubscribeParameterUpdates m, Output& out) {
    if (m.names.empty()) {
        all_parameters_ = true;
        out.events.push_back(event::ParametersSubscribed{{}, true});
        return;
    }
    std::vector<std::string> added;
    for (auto& name : m.names)
        if (!parameters_.count(name)) added.push_back(name);
    std::sort(added.begin(), added.end());
    added.erase(std::unique(added.begin(), added.end()), added.end());
    if (parameters_.size() + added.size() > limits_.max_parameter_subscriptions)
        return error_status(out, "subscribeParameterUpdates refused: more than " + n(limits_.max_parameter_subscriptions) +
                                     " parameter subscriptions on this connection");
    for (const auto& name : added) parameters_.insert(name);
    if (!added.empty()) out.events.push_back(event::ParametersSubscribed{std::move(added), false});
}

void Session::on(const UnsubscribeParameterUpdates& m, Output&) {
    if (m.names.empty()) {
        parameters_.clear();
        all_parameters_ = false;
        return;
    }
    for (const auto& name : m.names) parameters_.erase(name);
}

void Session::on(const SubscribeConnectionGraph&, Output& out) {
    error_status(out, "subscribeConnectionGraph: this server does not offer the connectionGraph capability");
}
void Session::on(const UnsubscribeConnectionGraph&, Output& out) {
    error_status(out, "unsubscribeConnectionGraph: this server does not offer the connectionGraph capability");
}
void Session::on(const FetchAsset& m, Output& out) {
    error_status(out, "fetchAsset " + m.uri + ": this server does not offer the assets capability");
}

void Session::on(const ClientMessageData& m, Output& out) {
    auto it = client_channels_.find(m.channel_id);
    if (it == client_channels_.end())
        return error_status(out, "message refused: client channel " + n(m.channel_id) + " is not advertised");
    out.events.push_back(event::ClientPublish{&it->second, m.payload});
}

void Session::on(ServiceCallRequest m, Output& out) {
    if (!services_.count(m.service_id)) {
        out.texts.push_back(service_call_failure_json(m.service_id, m.call_id, "service " + n(m.service_id) + " is not advertised"));
        return;
    }
    if (!encoding_supported(m.encoding)) {
        out.texts.push_back(service_call_failure_json(m.service_id, m.call_id,
                                                      "encoding \"" + m.encoding + "\" is not supported; this server takes json"));
        return;
    }
    if (calls_.count({m.service_id, m.call_id})) {
        out.texts.push_back(service_call_failure_json(m.service_id, m.call_id, "call id " + n(m.call_id) + " is already in flight"));
        return;
    }
    if (calls_.size() >= limits_.max_calls_in_flight) {
        out.texts.push_back(service_call_failure_json(
            m.service_id, m.call_id, "more than " + n(limits_.max_calls_in_flight) + " service calls in flight on this connection"));
        return;
    }
    calls_.insert({m.service_id, m.call_id});
    out.events.push_back(event::ServiceCall{m.service_id, m.call_id, std::move(m.encoding), m.payload});
}

void Session::channels_advertised(const std::vector<Channel>& channels) {
    for (const auto& c : channels) channels_.insert(c.id);
}

std::vector<event::Unsubscribed> Session::channels_unadvertised(const std::vector<std::uint32_t>& channel_ids) {
    std::vector<event::Unsubscribed> ended;
    for (auto id : channel_ids) {
        channels_.erase(id);
        auto it = channel_subscription_.find(id);
        if (it == channel_subscription_.end()) continue;
        ended.push_back(event::Unsubscribed{it->second, id});
        subscriptions_.erase(it->second);
        channel_subscription_.erase(it);
    }
    return ended;
}

void Session::services_advertised(const std::vector<Service>& services) {
    for (const auto& s : services) services_.insert(s.id);
}

void Session::services_unadvertised(const std::vector<std::uint32_t>& service_ids) {
    for (auto id : service_ids) services_.erase(id);
}

void Session::end_subscription(std::uint32_t subscription_id) {
    auto it = subscriptions_.find(subscription_id);
    if (it == subscriptions_.end()) return;
    channel_subscription_.erase(it->second);
    subscriptions_.erase(it);
}

void Session::call_finished(std::uint32_t service_id, std::uint32_t call_id) { calls_.erase({service_id, call_id}); }

std::optional<std::uint32_t> Session::subscription_channel(std::uint32_t subscription_id) const {
    auto it = subscriptions_.find(subscription_id);
    if (it == subscriptions_.end()) return std::nullopt;
    return it->second;
}

}  // namespace rr::foxglove
