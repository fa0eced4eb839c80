// The Foxglove server: what is advertised (every connected device's channels and services, ids kept per
// topic and schema across reconnects), the connections, and the handler on both subprotocols.
#include "server/foxglove/foxglove_server.hpp"

#include "server/common/random_ids.hpp"
#include "server/foxglove/foxglove_clock.hpp"
#include "server/foxglove/foxglove_connection.hpp"
#include "server/node/node.hpp"

namespace rr::server::foxglove {

FoxgloveServer::FoxgloveServer(std::shared_ptr<gateway::JsonApi> api, boost::asio::any_io_executor executor, FoxgloveOptions options)
    : api_(std::move(api)),
      executor_(executor),
      options_(std::move(options)),
      session_id_(random_service_state_nonce()),
      convert_strand_(boost::asio::make_strand(executor)) {}

std::shared_ptr<FoxgloveServer> FoxgloveServer::create(std::shared_ptr<gateway::JsonApi> api, boost::asio::any_io_executor executor,
                                                       FoxgloveOptions options) {
    std::shared_ptr<FoxgloveServer> s(new FoxgloveServer(std::move(api), executor, std::move(options)));
    std::weak_ptr<FoxgloveServer> weak_server = s;
    s->clock_ = std::make_shared<FoxgloveClock>(s->api_, s->options_.time_interval, [weak_server] {
        if (auto self = weak_server.lock())
            for (const auto& c : self->connections()) c->time();
    });
    for (const auto& d : s->api_->devices()) s->watch(d);
    std::weak_ptr<FoxgloveServer> weak = s;
    s->devices_listener_ = s->api_->add_devices_listener([weak](const std::shared_ptr<gateway::DeviceMirror>& d, bool added) {
        auto self = weak.lock();
        if (!self) return;
        if (added) return self->watch(d);
        {
            std::lock_guard lock(self->mutex_);
            for (auto it = self->listeners_.begin(); it != self->listeners_.end();) {
                if (it->first == d) {
                    d->remove_state_listener(it->second);
                    it = self->listeners_.erase(it);
                } else {
                    ++it;
                }
            }
        }
        self->device_down(d->config().name);
    });
    return s;
}

FoxgloveServer::~FoxgloveServer() {
    api_->remove_devices_listener(devices_listener_);
    for (auto& [d, id] : listeners_) d->remove_state_listener(id);
    decltype(connections_) conns;
    {
        std::lock_guard lock(mutex_);
        conns.swap(connections_);
    }
    for (auto& [k, c] : conns) c->close();
}

void FoxgloveServer::watch(const std::shared_ptr<gateway::DeviceMirror>& device) {
    std::weak_ptr<FoxgloveServer> weak = weak_from_this();
    std::weak_ptr<gateway::DeviceMirror> weak_device = device;
    const auto id = device->add_state_listener([weak, weak_device](const gateway::DeviceStatus& status) {
        auto self = weak.lock();
        auto d = weak_device.lock();
        if (self && d) self->on_device_state(d, status);
    });
    {
        std::lock_guard lock(mutex_);
        listeners_.emplace_back(device, id);
    }
    on_device_state(device, device->status());
}

void FoxgloveServer::on_device_state(const std::shared_ptr<gateway::DeviceMirror>& device, const gateway::DeviceStatus& status) {
    if (status.state == gateway::DeviceState::connected)
        device_up(device);
    else
        device_down(device->config().name);
}

std::uint32_t FoxgloveServer::id_for(const std::string& key, std::map<std::string, std::uint32_t>& ids, std::uint32_t& next) {
    auto [it, added] = ids.emplace(key, next);
    if (added) ++next;
    return it->second;
}

void FoxgloveServer::device_up(const std::shared_ptr<gateway::DeviceMirror>& device) {
    const std::string name = device->config().name;
    std::vector<std::string> objects;
    if (auto it = options_.objects.find(name); it != options_.objects.end()) objects = it->second;
    auto members = device_members(*api_, device, objects);
    // An object path of the configuration that does not resolve on this device: the root alone.
    if (!members && !objects.empty() && members.error().type == MessageErrorType::InvalidArgument)
        members = device_members(*api_, device, {});
    if (!members) return;  // not usable yet (definitions); the next state change tries again
    Catalog added;
    std::optional<LiveMember> clock_wire;
    {
        std::lock_guard lock(mutex_);
        if (devices_.count(name)) return;  // advertised already
        // Foxglove's time: the named device's clock, else a standard clock device's (the first).
        if (const LiveMember* w = find_clock_wire(*members))
            if (options_.clock == name || (options_.clock.empty() && is_clock_device(*device) && clock_->device().empty()))
                clock_wire = *w;
        DeviceEntry entry;
        for (auto& m : *members) {
            auto live = std::make_shared<const LiveMember>(std::move(m));
            switch (live->kind) {
                case LiveKind::wire:
                case LiveKind::pipe:
                case LiveKind::event: {
                    fg::Channel c{0, live->topic, "json", live->schema_name, live->schema, "jsonschema"};
                    c.id = id_for(c.topic + '\n' + c.schema_name + '\n' + c.schema, channel_ids_, next_channel_);
                    channels_[c.id] = {c, live};
                    entry.channel_ids.push_back(c.id);
                    added.channels.push_back(std::move(c));
                    break;
                }
                case LiveKind::function: {
                    fg::Service s;
                    s.name = live->topic;
                    s.type = live->schema_name;
                    s.request = {"json", live->schema_name + " request", "jsonschema", live->schema};
                    s.response = {"json", live->schema_name + " response", "jsonschema", live->response_schema};
                    s.id = id_for(s.name + '\n' + s.type + '\n' + s.request.schema + '\n' + s.response.schema, service_ids_, next_service_);
                    services_[s.id] = {s, live};
                    entry.service_ids.push_back(s.id);
                    added.services.push_back(std::move(s));
                    break;
                }
                case LiveKind::property: properties_[live->topic] = live; break;
            }
        }
        devices_[name] = std::move(entry);
    }
    if (clock_wire) clock_->follow(*clock_wire, *clock_wire_kind(*clock_wire));
    for (const auto& c : connections()) c->advertise(added);
}

bool FoxgloveServer::offers_time() const { return !options_.clock.empty() || !clock_->device().empty(); }

void FoxgloveServer::device_down(const std::string& name) {
    clock_->device_gone(name);
    DeviceEntry entry;
    {
        std::lock_guard lock(mutex_);
        auto it = devices_.find(name);
        if (it == devices_.end()) return;
        entry = std::move(it->second);
        devices_.erase(it);
        for (auto id : entry.channel_ids) channels_.erase(id);
        for (auto id : entry.service_ids) services_.erase(id);
        for (auto p = properties_.begin(); p != properties_.end();) {
            if (p->second->target->device->config().name == name)
                p = properties_.erase(p);
            else
                ++p;
        }
    }
    for (const auto& c : connections()) c->unadvertise(entry.channel_ids, entry.service_ids);
}

std::vector<std::shared_ptr<FoxgloveConnection>> FoxgloveServer::connections() const {
    std::vector<std::shared_ptr<FoxgloveConnection>> out;
    std::lock_guard lock(mutex_);
    for (const auto& [k, c] : connections_) out.push_back(c);
    return out;
}

FoxgloveServer::Catalog FoxgloveServer::catalog() const {
    Catalog c;
    std::lock_guard lock(mutex_);
    for (const auto& [id, ch] : channels_) c.channels.push_back(ch.first);
    for (const auto& [id, s] : services_) c.services.push_back(s.first);
    return c;
}

std::shared_ptr<const LiveMember> FoxgloveServer::channel_member(std::uint32_t id) const {
    std::lock_guard lock(mutex_);
    auto it = channels_.find(id);
    return it == channels_.end() ? nullptr : it->second.second;
}

std::shared_ptr<const LiveMember> FoxgloveServer::service_member(std::uint32_t id) const {
    std::lock_guard lock(mutex_);
    auto it = services_.find(id);
    return it == services_.end() ? nullptr : it->second.second;
}

std::shared_ptr<const LiveMember> FoxgloveServer::member_named(const std::string& topic, LiveKind kind) const {
    std::lock_guard lock(mutex_);
    if (kind == LiveKind::property) {
        auto it = properties_.find(topic);
        return it == properties_.end() ? nullptr : it->second;
    }
    for (const auto& [id, ch] : channels_)
        if (ch.second->topic == topic && ch.second->kind == kind) return ch.second;
    return nullptr;
}

std::vector<std::shared_ptr<const LiveMember>> FoxgloveServer::properties() const {
    std::vector<std::shared_ptr<const LiveMember>> out;
    std::lock_guard lock(mutex_);
    for (const auto& [name, m] : properties_) out.push_back(m);
    return out;
}

void FoxgloveServer::parameter_changed(const fg::Parameter& p) {
    for (const auto& c : connections()) c->parameter_changed(p);
}

std::vector<FoxgloveStats> FoxgloveServer::stats() const {
    std::vector<FoxgloveStats> out;
    for (const auto& c : connections()) out.push_back(c->stats());
    return out;
}

http::JsonSocketHandler FoxgloveServer::handler() {
    std::weak_ptr<FoxgloveServer> weak = weak_from_this();
    auto find = [weak](const std::shared_ptr<http::JsonSocket>& s) -> std::shared_ptr<FoxgloveConnection> {
        auto self = weak.lock();
        if (!self) return nullptr;
        std::lock_guard lock(self->mutex_);
        auto it = self->connections_.find(s.get());
        return it == self->connections_.end() ? nullptr : it->second;
    };
    http::JsonSocketHandler h;
    h.on_open = [weak](std::shared_ptr<http::JsonSocket> s) {
        auto self = weak.lock();
        if (!self) return s->close();
        auto c = std::make_shared<FoxgloveConnection>(weak, self->api_, s, self->executor_, self->convert_strand_, self->options_,
                                                     self->clock_);
        {
            std::lock_guard lock(self->mutex_);
            self->connections_[s.get()] = c;
        }
        c->start();
    };
    h.on_message = [find](const std::shared_ptr<http::JsonSocket>& s, std::string text) {
        if (auto c = find(s)) c->on_text(std::move(text));
    };
    h.on_binary = [find](const std::shared_ptr<http::JsonSocket>& s, std::string bytes) {
        if (auto c = find(s)) c->on_binary(std::move(bytes));
    };
    h.on_close = [weak](const std::shared_ptr<http::JsonSocket>& s) {
        auto self = weak.lock();
        if (!self) return;
        std::shared_ptr<FoxgloveConnection> c;
        {
            std::lock_guard lock(self->mutex_);
            auto it = self->connections_.find(s.get());
            if (it == self->connections_.end()) return;
            c = std::move(it->second);
            self->connections_.erase(it);
        }
        c->close();
    };
    return h;
}

std::shared_ptr<FoxgloveServer> install_foxglove(http::HttpServer& http, std::shared_ptr<gateway::JsonApi> api, FoxgloveOptions options) {
    auto node = http.node();
    boost::asio::any_io_executor executor = node ? node->io_context().get_executor() : boost::asio::any_io_executor{};
    auto server = FoxgloveServer::create(std::move(api), executor, std::move(options));
    // The registered handler holds the server (as the JSON WebSocket's does).
    http::JsonSocketHandler h = server->handler();
    h.on_open = [server, open = h.on_open](std::shared_ptr<http::JsonSocket> s) { open(std::move(s)); };
    http.add_subprotocol(std::string(fg::kSubprotocolV1), h);
    http.add_subprotocol(std::string(fg::kSubprotocolSdk), h);
    return server;
}

}  // namespace rr::server::foxglove
