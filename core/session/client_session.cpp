#include "core/session/client_session.hpp"

#include <algorithm>

#include "core/core_version.hpp"
#include "core/session/elements.hpp"

namespace rr {
namespace {

constexpr std::chrono::milliseconds kDisconnectWait{500};

MessageElement make_credentials_element(const ClientSessionConfig& config) {
    if (config.credentials) {
        MessageElement creds = *config.credentials;
        creds.name = "credentials";
        creds.number.reset();
        return creds;
    }
    const std::string& password = config.password;
    // credentials: map{string} of varvalue, normally {"password": <string>} (wire.md §6.4).
    MessageElement creds;
    creds.name = "credentials";
    creds.type = DataTypes::dictionary_t;
    creds.elements.push_back(make_string_element("password", password));
    return creds;
}

// The `import` names of a robdef text, found by a line scan (the full parser is not needed here).
std::vector<std::string> scan_imports(std::string_view text) {
    std::vector<std::string> out;
    std::size_t pos = 0;
    while (pos < text.size()) {
        auto end = text.find('\n', pos);
        auto line = text.substr(pos, end == std::string_view::npos ? std::string_view::npos : end - pos);
        pos = end == std::string_view::npos ? text.size() : end + 1;
        auto b = line.find_first_not_of(" \t");
        if (b == std::string_view::npos) continue;
        line = line.substr(b);
        if (line.rfind("import", 0) != 0 || line.size() < 7 || (line[6] != ' ' && line[6] != '\t')) continue;
        line = line.substr(6);
        auto s = line.find_first_not_of(" \t");
        if (s == std::string_view::npos) continue;
        line = line.substr(s);
        auto e = line.find_last_not_of(" \t\r");
        out.emplace_back(line.substr(0, e + 1));
    }
    return out;
}

// The `service` name declared by a robdef text.
std::string scan_service_name(std::string_view text) {
    std::size_t pos = 0;
    while (pos < text.size()) {
        auto end = text.find('\n', pos);
        auto line = text.substr(pos, end == std::string_view::npos ? std::string_view::npos : end - pos);
        pos = end == std::string_view::npos ? text.size() : end + 1;
        auto b = line.find_first_not_of(" \t");
        if (b == std::string_view::npos) continue;
        line = line.substr(b);
        if (line.rfind("service", 0) == 0 && line.size() > 8 && (line[7] == ' ' || line[7] == '\t')) {
            line = line.substr(8);
            auto s = line.find_first_not_of(" \t");
            auto e = line.find_last_not_of(" \t\r");
            if (s == std::string_view::npos) return {};
            return std::string(line.substr(s, e - s + 1));
        }
    }
    return {};
}

std::vector<std::string> read_string_list(const MessageElement& e) {
    std::vector<std::string> out;
    if (e.type != DataTypes::list_t) return out;
    for (const auto& item : e.elements) out.emplace_back(read_string(item));
    return out;
}

}  // namespace

std::string seconds_text(std::chrono::milliseconds d) {
    const auto ms = d.count();
    std::string s = std::to_string(ms / 1000);
    if (auto frac = ms % 1000; frac != 0) {
        std::string f = std::to_string(1000 + frac).substr(1);  // three digits
        while (f.back() == '0') f.pop_back();
        s += "." + f;
    }
    return s + " s";
}

RRError service_not_found_error(std::string_view service, std::string_view remote_message) {
    const std::string quoted = "\"" + std::string(service) + "\"";
    std::string message = "service " + quoted + " not found";
    // Keep what the node said when it adds something (CORE says only "Service not found").
    if (!remote_message.empty() && remote_message.find(quoted) == std::string_view::npos &&
        remote_message != "Service not found")
        message += " (" + std::string(remote_message) + ")";
    return make_error(MessageErrorType::ServiceNotFound, std::move(message));
}

ClientSession::ClientSession(ClientSessionConfig config, MonoTime now)
    : config_(std::move(config)), stream_(StreamRole::client, config_.stream, now), last_send_(now),
      connect_deadline_(now + config_.request_timeout), disconnect_deadline_(now) {
    if (config_.connect_timeout.count() > 0) connect_limit_ = now + config_.connect_timeout;
}

std::uint32_t ClientSession::next_request_id() {
    // Per-client counter from 1, wrapping through 0 as CORE does (wire.md §6.4); 0 itself is skipped.
    if (++request_counter_ == 0) ++request_counter_;
    return request_counter_;
}

Result<void> ClientSession::feed(std::span<const std::byte> bytes, MonoTime now) {
    if (state_ == State::closed) return fail(MessageErrorType::ConnectionError, "session closed");
    auto r = stream_.feed(bytes, now);
    drain_stream(now);
    return r;
}

void ClientSession::on_transport_closed(RRError error) {
    stream_.on_transport_closed(error);
    drain_stream(MonoTime{});
    close(std::move(error));
}

void ClientSession::drain_stream(MonoTime now) {
    // Handled in place (no move per message). Handling runs no host code and never drains the stream
    // itself, so the one batch vector is never in use twice; events queued meanwhile come next round.
    for (stream_.take_events(stream_batch_); !stream_batch_.empty(); stream_.take_events(stream_batch_))
        for (auto& ev : stream_batch_) on_stream_event(std::move(ev), now);
}

void ClientSession::on_stream_event(StreamEvent&& ev, MonoTime now) {
    if (auto* c = std::get_if<StreamConnected>(&ev)) {
        (void)c;
        start_connect(now);
    } else if (auto* m = std::get_if<StreamMessage>(&ev)) {
        on_message(std::move(m->message), now);
    } else if (auto* closed = std::get_if<StreamClosed>(&ev)) {
        close(std::move(closed->error));
    }
}

Result<void> ClientSession::send_special(MessageEntry&& entry, MonoTime now, std::uint32_t receiver_endpoint) {
    Message m;
    m.entries = stream_.entry_vectors().take();
    m.version = 2;
    m.header.sender_node_id = config_.stream.local_node_id;
    m.header.sender_node_name = config_.stream.local_node_name;
    m.header.receiver_node_id = stream_.negotiated().remote_node_id;
    m.header.receiver_node_name = stream_.negotiated().remote_node_name;
    m.header.sender_endpoint = config_.local_endpoint;
    m.header.receiver_endpoint = receiver_endpoint;
    m.header.message_id = ++message_id_;
    m.entries.push_back(std::move(entry));
    last_send_ = now;
    return stream_.send(std::move(m), now);
}

Result<void> ClientSession::send_session(MessageEntry&& entry, MonoTime now) {
    Message m;
    m.entries = stream_.entry_vectors().take();
    m.version = 2;
    m.header.sender_node_id = config_.stream.local_node_id;
    m.header.receiver_node_id = stream_.negotiated().remote_node_id;
    m.header.sender_endpoint = config_.local_endpoint;
    m.header.receiver_endpoint = remote_endpoint_;
    m.header.message_id = ++message_id_;
    if (entry.metadata == "unreliable\n") m.header.metadata = entry.metadata;  // wire.md §1.6
    m.entries.push_back(std::move(entry));
    last_send_ = now;
    return stream_.send(std::move(m), now);
}

void ClientSession::start_connect(MonoTime now) {
    connect_deadline_ = now + config_.request_timeout;
    MessageEntry e;
    e.service_path = config_.service_name;
    e.request_id = connect_request_id_ = next_request_id();
    e.elements.push_back(make_string_element("clientversion", kProtocolClientVersion));
    if (stream_.negotiated().connect_combined) {
        state_ = State::combined_connect;
        e.entry_type = MessageEntryType::ConnectClientCombined;
        e.elements.push_back(make_string_element("returnservicedefs", "true"));
        if (!config_.username.empty()) {
            e.elements.push_back(make_string_element("username", config_.username));
            e.elements.push_back(make_credentials_element(config_));
        }
    } else {
        state_ = State::legacy_servicedesc;
        e.entry_type = MessageEntryType::GetServiceDesc;
    }
    if (auto r = send_special(std::move(e), now); !r) fail_connect(r.error());
}

void ClientSession::request_missing_definitions(MonoTime now) {
    // Legacy path: ask for each import not yet known, one at a time (wire.md §6.4 B.2).
    while (!pending_imports_.empty()) {
        std::string name = pending_imports_.back();
        pending_imports_.pop_back();
        bool known = false;
        for (const auto& def : info_.service_definitions)
            if (scan_service_name(def) == name) known = true;
        if (known) continue;
        MessageEntry e;
        e.entry_type = MessageEntryType::GetServiceDesc;
        e.service_path = config_.service_name;
        e.request_id = connect_request_id_ = next_request_id();
        e.elements.push_back(make_string_element("ServiceType", name));
        e.elements.push_back(make_string_element("clientversion", kProtocolClientVersion));
        state_ = State::legacy_servicedesc;
        if (auto r = send_special(std::move(e), now); !r) fail_connect(r.error());
        return;
    }
    // All definitions known: ObjectTypeName for the root.
    MessageEntry e;
    e.entry_type = MessageEntryType::ObjectTypeName;
    e.service_path = config_.service_name;
    e.request_id = connect_request_id_ = next_request_id();
    e.elements.push_back(make_string_element("clientversion", kProtocolClientVersion));
    state_ = State::legacy_objecttype;
    if (auto r = send_special(std::move(e), now); !r) fail_connect(r.error());
}

void ClientSession::on_connect_reply(MessageEntry&& e, const MessageHeader& h, MonoTime now) {
    if (e.error != MessageErrorType::None) {
        RRError error = *entry_error(e);
        // The service itself is unknown (not one of its imported definitions): name it, under the
        // standard name. CORE sends "RobotRaconteur.ServiceNotFoundException" / "Service not found".
        if (error.type == MessageErrorType::ServiceNotFound &&
            (state_ != State::legacy_servicedesc || info_.service_definitions.empty()))
            error = service_not_found_error(config_.service_name, error.message);
        fail_connect(std::move(error));
        return;
    }
    switch (state_) {
        case State::combined_connect: {
            if (const auto* t = e.find("objecttype")) info_.object_type = std::string(read_string(*t));
            if (const auto* i = e.find("objectimplements")) info_.object_implements = read_string_list(*i);
            if (const auto* d = e.find("servicedefs")) info_.service_definitions = read_string_list(*d);
            if (const auto* a = e.find("attributes")) info_.attributes = *a;
            remote_endpoint_ = h.sender_endpoint;
            break;
        }
        case State::legacy_servicedesc: {
            const auto* d = e.find("servicedef");
            if (!d) {
                fail_connect(make_error(MessageErrorType::ProtocolError, "GetServiceDescRet without servicedef"));
                return;
            }
            std::string text(read_string(*d));
            const bool root = info_.service_definitions.empty();
            if (root) {
                if (const auto* a = e.find("attributes")) info_.attributes = *a;
                if (const auto* x = e.find("extraimports"))
                    for (auto& name : read_string_list(*x)) pending_imports_.push_back(std::move(name));
            }
            for (auto& name : scan_imports(text)) pending_imports_.push_back(std::move(name));
            info_.service_definitions.push_back(std::move(text));
            request_missing_definitions(now);
            return;
        }
        case State::legacy_objecttype: {
            if (const auto* t = e.find("objecttype")) info_.object_type = std::string(read_string(*t));
            if (const auto* i = e.find("objectimplements")) info_.object_implements = read_string_list(*i);
            MessageEntry c;
            c.entry_type = MessageEntryType::ConnectClient;
            c.service_path = config_.service_name;
            c.request_id = connect_request_id_ = next_request_id();
            state_ = State::legacy_connect;
            if (auto r = send_special(std::move(c), now); !r) fail_connect(r.error());
            return;
        }
        case State::legacy_connect: {
            remote_endpoint_ = h.sender_endpoint;
            if (!config_.username.empty()) {
                stream_.set_session_established(config_.local_endpoint, remote_endpoint_);
                MessageEntry a;
                a.entry_type = MessageEntryType::ClientSessionOpReq;
                a.member_name = "AuthenticateUser";
                a.service_path = config_.service_name;
                a.request_id = connect_request_id_ = next_request_id();
                a.elements.push_back(make_string_element("username", config_.username));
                a.elements.push_back(make_credentials_element(config_));
                state_ = State::legacy_authenticate;
                if (auto r = send_session(std::move(a), now); !r) fail_connect(r.error());
                return;
            }
            break;
        }
        case State::legacy_authenticate: break;
        default: return;
    }
    if (remote_endpoint_ == 0) {
        fail_connect(make_error(MessageErrorType::ProtocolError, "service endpoint 0 in connect reply"));
        return;
    }
    stream_.set_session_established(config_.local_endpoint, remote_endpoint_);
    state_ = State::connected;
    events_.push_back(ClientSessionConnected{info_});
}

void ClientSession::on_message(Message&& m, MonoTime now) {
    on_entries(m, now);
    stream_.entry_vectors().give(std::move(m.entries));
}

void ClientSession::on_entries(Message& m, MonoTime now) {
    for (auto& e : m.entries) {
        const bool connecting = state_ == State::combined_connect || state_ == State::legacy_servicedesc ||
                                state_ == State::legacy_objecttype || state_ == State::legacy_connect ||
                                state_ == State::legacy_authenticate;
        if (connecting) {
            if (e.request_id == connect_request_id_ && !is_request(e.entry_type)) on_connect_reply(std::move(e), m.header, now);
            continue;
        }
        if (state_ == State::disconnecting) {
            if (e.entry_type == MessageEntryType::DisconnectClientRet)
                close(make_error(MessageErrorType::ConnectionError, "disconnected"));
            continue;
        }
        if (state_ != State::connected) return;
        switch (e.entry_type) {
            case MessageEntryType::ClientKeepAliveRet: continue;
            case MessageEntryType::ServiceClosed:
                events_.emplace_back(std::in_place_type<ClientIncoming>, std::move(e));
                close(make_error(MessageErrorType::ServiceNotFound, "service closed"));
                return;
            default: break;
        }
        if (!is_request(e.entry_type) && e.entry_type != MessageEntryType::PipePacketRet) {
            auto it = pending_.find(e.request_id);
            if (it != pending_.end()) {
                pending_.erase(it);
                const std::uint32_t id = e.request_id;
                events_.emplace_back(std::in_place_type<ClientResponse>, id, std::move(e));
            }
            // An answer to a forgotten or timed-out request is dropped.
            continue;
        }
        events_.emplace_back(std::in_place_type<ClientIncoming>, std::move(e));
    }
}

Result<std::uint32_t> ClientSession::request(MessageEntry&& entry, MonoTime now) {
    return request(std::move(entry), now, config_.request_timeout);
}

Result<std::uint32_t> ClientSession::request(MessageEntry&& entry, MonoTime now, std::chrono::milliseconds timeout) {
    if (state_ != State::connected) return fail(MessageErrorType::InvalidState, "client session not connected");
    const std::uint32_t id = next_request_id();
    entry.request_id = id;
    if (auto r = send_session(std::move(entry), now); !r) return r.take_error();
    Pending p;
    p.has_deadline = timeout.count() > 0;
    p.deadline = now + timeout;
    pending_.put(id, p);
    return id;
}

Result<void> ClientSession::send_packet(MessageEntry&& entry, MonoTime now) {
    if (state_ != State::connected) return fail(MessageErrorType::InvalidState, "client session not connected");
    return send_session(std::move(entry), now);
}

Result<void> ClientSession::reply(MessageEntry&& entry, MonoTime now) { return send_packet(std::move(entry), now); }

void ClientSession::forget_request(std::uint32_t request_id) { pending_.erase(request_id); }

void ClientSession::disconnect(MonoTime now) {
    if (state_ == State::closed || state_ == State::disconnecting) return;
    if (state_ != State::connected) {
        close(make_error(MessageErrorType::ConnectionError, "disconnected"));
        return;
    }
    MessageEntry e;
    e.entry_type = MessageEntryType::DisconnectClient;
    e.request_id = next_request_id();
    e.elements.push_back(make_string_element("servicename", config_.service_name));
    (void)send_special(std::move(e), now, remote_endpoint_);
    state_ = State::disconnecting;
    disconnect_deadline_ = now + kDisconnectWait;
}

std::optional<MonoTime> ClientSession::next_deadline() const {
    if (state_ == State::closed) return std::nullopt;
    std::optional<MonoTime> d = stream_.next_deadline();
    auto take = [&](MonoTime t) { d = d ? std::min(*d, t) : t; };
    if (connect_limit_ && state_ != State::connected && state_ != State::disconnecting) take(*connect_limit_);
    switch (state_) {
        case State::connected:
            take(last_send_ + config_.keepalive_period);
            for (const auto& [id, p] : pending_)
                if (p.has_deadline) take(p.deadline);
            break;
        case State::disconnecting: take(disconnect_deadline_); break;
        case State::stream_connecting: break;
        default: take(connect_deadline_); break;
    }
    return d;
}

void ClientSession::on_timer(MonoTime now) {
    if (connect_limit_ && now >= *connect_limit_ && state_ != State::connected && state_ != State::disconnecting &&
        state_ != State::closed) {
        fail_connect(make_error(MessageErrorType::ConnectionError,
                                "connect timed out after " + seconds_text(config_.connect_timeout) +
                                    (state_ == State::stream_connecting
                                         ? ": the peer did not answer CreateConnection"
                                         : ": the service did not answer the connect request")));
        return;
    }
    stream_.on_timer(now);
    drain_stream(now);
    switch (state_) {
        case State::closed:
        case State::stream_connecting: return;
        case State::disconnecting:
            if (now >= disconnect_deadline_) close(make_error(MessageErrorType::ConnectionError, "disconnected"));
            return;
        case State::connected: break;
        default:
            if (now >= connect_deadline_)
                fail_connect(make_error(MessageErrorType::RequestTimeout, "connect to service timed out"));
            return;
    }
    for (auto it = pending_.begin(); it != pending_.end();) {
        if (it->second.has_deadline && now >= it->second.deadline) {
            events_.push_back(ClientResponse{it->first, fail(MessageErrorType::RequestTimeout, "request timed out")});
            it = pending_.erase(it);
        } else {
            ++it;
        }
    }
    if (now - last_send_ >= config_.keepalive_period) {
        MessageEntry k;
        k.entry_type = MessageEntryType::ClientKeepAliveReq;
        k.service_path = config_.service_name;
        (void)send_session(std::move(k), now);
    }
}

std::optional<ClientSessionEvent> ClientSession::poll_event() {
    return events_.pop();
}

void ClientSession::fail_connect(RRError error) { close(std::move(error)); }

void ClientSession::close(RRError error) {
    if (state_ == State::closed) return;
    state_ = State::closed;
    for (const auto& [id, p] : pending_)
        events_.push_back(ClientResponse{id, fail(make_error(MessageErrorType::ConnectionError, "connection closed: " + error.message))});
    pending_.clear();
    events_.push_back(ClientSessionClosed{std::move(error)});
}

}  // namespace rr
