#include "server/gateway/passthrough_sessions.hpp"

#include <algorithm>

#include "base/message/error_entry.hpp"
#include "base/names/service_path.hpp"
#include "core/session/elements.hpp"
#include "server/gateway/device_mirror.hpp"

namespace rr::server::gateway {
namespace {

bool is_lock_op(const std::string& op) {
    return op == "RequestObjectLock" || op == "RequestClientObjectLock" || op == "ReleaseObjectLock" ||
           op == "ReleaseClientObjectLock" || op == "MonitorEnter" || op == "MonitorContinueEnter" || op == "MonitorExit";
}

std::string reply_return(const MessageEntry& reply) {
    if (const auto* r = reply.find("return"); r && r->type == DataTypes::string_t) return std::string(read_string(*r));
    return {};
}

}  // namespace

PassthroughSessions::PassthroughSessions(boost::asio::any_io_executor executor, Settings settings,
                                         std::weak_ptr<DeviceCounters> counters)
    : executor_(std::move(executor)), settings_(std::move(settings)), counters_(std::move(counters)) {}

PassthroughSessions::~PassthroughSessions() { close_all(); }

std::string PassthroughSessions::to_upstream(std::string_view path) const {
    return replace_service_name(path, settings_.upstream_service);
}
std::string PassthroughSessions::to_downstream(std::string_view path) const {
    return replace_service_name(path, settings_.device_name);
}

void PassthroughSessions::admit(std::uint32_t endpoint, std::string username, std::optional<MessageElement> credentials,
                                std::function<void(Result<void>)> done) {
    std::optional<RRError> refused;
    {
        std::lock_guard lock(mutex_);
        if (closed_) {
            refused = make_error(MessageErrorType::ConnectionError, "device \"" + settings_.device_name + "\" is stopping");
        } else if (links_.size() >= settings_.max_sessions) {
            refused = make_error(MessageErrorType::BufferLimitViolation,
                                 "device \"" + settings_.device_name + "\": passthrough session limit (" +
                                     std::to_string(settings_.max_sessions) + " upstream sessions) reached; try again later");
        } else {
            Link link;
            link.username = username;
            links_[endpoint] = std::move(link);
            gone_.erase(endpoint);
        }
    }
    if (refused) {
        done(fail(*refused));
        return;
    }
    RawClientOptions options = settings_.options;
    options.username = username;
    options.password.clear();
    options.credentials = std::move(credentials);
    // The client's username without credentials: sent with an empty credentials map, so the device
    // answers as it would to the client itself.
    if (!username.empty() && !options.credentials) {
        MessageElement empty;
        empty.name = "credentials";
        empty.type = DataTypes::dictionary_t;
        options.credentials = std::move(empty);
    }
    std::weak_ptr<PassthroughSessions> weak = weak_from_this();
    RawClient::connect(
        executor_, settings_.url, std::move(options),
        [weak, endpoint](MessageEntry&& e) {
            if (auto self = weak.lock()) self->from_device(endpoint, std::move(e));
        },
        [weak, endpoint](const RRError& error) {
            if (auto self = weak.lock()) self->upstream_closed(endpoint, error);
        },
        [weak, endpoint, done = std::move(done)](Result<std::shared_ptr<RawClient>> r) {
            auto self = weak.lock();
            if (!self) {
                if (r) (*r)->close();
                done(fail(MessageErrorType::ConnectionError, "gateway device stopped"));
                return;
            }
            if (!r) {
                {
                    std::lock_guard lock(self->mutex_);
                    self->links_.erase(endpoint);
                    self->gone_.erase(endpoint);
                }
                done(r.take_error());
                return;
            }
            bool keep = false;
            {
                std::lock_guard lock(self->mutex_);
                auto it = self->links_.find(endpoint);
                keep = !self->closed_ && it != self->links_.end() && !self->gone_.count(endpoint);
                if (keep)
                    it->second.client = *r;
                else
                    self->links_.erase(endpoint);
                self->gone_.erase(endpoint);
            }
            if (!keep) {
                (*r)->close();
                done(fail(MessageErrorType::ConnectionError, "client gone while connecting"));
                return;
            }
            done({});
            self->changed();
        });
}

void PassthroughSessions::attach(const SessionRef& session) {
    std::vector<MessageEntry> early;
    std::shared_ptr<RawClient> client;
    std::shared_ptr<const DeliveryCheck> check;
    {
        std::lock_guard lock(mutex_);
        auto it = links_.find(session.endpoint());
        if (it == links_.end()) return;
        it->second.session = session;
        it->second.attached = true;
        early.swap(it->second.early);
        client = it->second.client;
        check = delivery_check_;
    }
    for (auto& e : early) deliver(session, client, check, std::move(e));
}

void PassthroughSessions::set_delivery_check(DeliveryCheck check) {
    auto c = check ? std::make_shared<const DeliveryCheck>(std::move(check)) : nullptr;
    std::lock_guard lock(mutex_);
    delivery_check_ = std::move(c);
}

void PassthroughSessions::attach_api(std::uint32_t endpoint, ApiHandlers handlers) {
    auto h = std::make_shared<const ApiHandlers>(std::move(handlers));
    bool lost = false;
    {
        std::lock_guard lock(mutex_);
        auto it = links_.find(endpoint);
        if (it == links_.end()) return;
        it->second.api = true;
        it->second.api_handlers = h;
        it->second.attached = true;
        it->second.early.clear();  // nothing is subscribed yet
        lost = it->second.lost;
    }
    if (lost && h->on_lost) h->on_lost(session_gone());
}

Result<void> PassthroughSessions::send(std::uint32_t endpoint, MessageEntry entry) {
    auto client = open_client(endpoint);
    if (!client) return fail(session_gone());
    entry.service_path = to_upstream(entry.service_path);
    if (entry.entry_type == MessageEntryType::PipePacket)
        if (auto k = counters_.lock()) k->pipe_packets.fetch_add(1);
    client->send(std::move(entry));
    return {};
}

std::size_t PassthroughSessions::queued_bytes(std::uint32_t endpoint) const {
    auto client = open_client(endpoint);
    return client ? client->queued_bytes() : 0;
}

void PassthroughSessions::close(std::uint32_t endpoint, std::function<void()> ended) {
    std::shared_ptr<RawClient> client;
    std::string username;
    bool found = false;
    {
        std::lock_guard lock(mutex_);
        auto it = links_.find(endpoint);
        if (it != links_.end()) {
            found = true;
            client = std::move(it->second.client);
            username = it->second.username;
            if (!client) gone_[endpoint];  // still connecting: the connect's answer closes it
            else links_.erase(it);
            forget_locks_of(endpoint, username);
        }
    }
    if (client)
        client->close(std::move(ended));  // `ended` once the device answered (or the session ended otherwise)
    else if (ended)
        ended();
    if (found) changed();
}

void PassthroughSessions::close_all() {
    std::vector<std::shared_ptr<RawClient>> clients;
    {
        std::lock_guard lock(mutex_);
        closed_ = true;
        for (auto& [ep, link] : links_)
            if (link.client) clients.push_back(std::move(link.client));
        links_.clear();
        locks_.clear();
    }
    for (auto& c : clients) c->close();
}

void PassthroughSessions::reopen() {
    std::lock_guard lock(mutex_);
    closed_ = false;
}

std::size_t PassthroughSessions::session_count() const {
    std::lock_guard lock(mutex_);
    return links_.size();
}

std::vector<DeviceLockInfo> PassthroughSessions::locks() const {
    std::lock_guard lock(mutex_);
    return locks_;
}

void PassthroughSessions::forget_locks_of(std::uint32_t endpoint, const std::string& username) {
    // Under mutex_. Client locks and monitors belong to the session; a user lock goes with the last
    // passthrough session of its user.
    bool user_has_other = false;
    for (const auto& [ep, link] : links_)
        if (ep != endpoint && link.username == username && !link.lost && !gone_.count(ep)) user_has_other = true;
    std::erase_if(locks_, [&](const DeviceLockInfo& l) {
        if (l.kind == "user") return l.username == username && !user_has_other;
        return l.endpoint == endpoint;
    });
}

std::shared_ptr<RawClient> PassthroughSessions::open_client(std::uint32_t endpoint) const {
    std::lock_guard lock(mutex_);
    auto it = links_.find(endpoint);
    if (it == links_.end() || it->second.lost || !it->second.client || !it->second.client->is_open()) return nullptr;
    return it->second.client;
}

RRError PassthroughSessions::session_gone() const {
    return make_error(MessageErrorType::ConnectionError,
                      "the device \"" + settings_.device_name + "\" closed this client's session");
}

void PassthroughSessions::handle_entry(const SessionRef& session, MessageEntry&& entry, Responder responder,
                                       std::function<void(const Result<MessageEntry>&)> observe, bool stop) {
    auto client = open_client(session.endpoint());
    if (!client) {
        if (observe) observe(fail(session_gone()));
        if (!responder.done()) responder.fail(session_gone());
        return;
    }
    if (responder.done()) {  // PipePacket, PipePacketRet, WirePacket: no answer
        entry.service_path = to_upstream(entry.service_path);
        client->send(std::move(entry));
        return;
    }
    auto shared = std::make_shared<Responder>(std::move(responder));
    std::optional<MessageEntry> again;
    if (stop) again = entry;  // a stop is small (halt(), one property value)
    const std::uint32_t endpoint = session.endpoint();
    std::weak_ptr<PassthroughSessions> weak = weak_from_this();
    forward(endpoint, client, std::move(entry),
            [shared, observe = std::move(observe), again = std::move(again), weak, endpoint](Result<MessageEntry> r) mutable {
                // By value: it may run later, from stop_as_lock_holder's own request.
                auto answer = [shared, observe](Result<MessageEntry> reply) {
                    if (observe) observe(reply);
                    if (!reply)
                        shared->fail(reply.error());
                    else
                        shared->respond(std::move(*reply));
                };
                auto self = weak.lock();
                if (!again || !self || !r || !self->refused_by_lock(*r)) return answer(std::move(r));
                // A lock another client took through the gateway refused the stop: sent again on that
                // client's session, which the lock does not bind.
                self->stop_as_lock_holder(endpoint, std::move(*again), std::move(answer), std::move(r));
            });
}

bool PassthroughSessions::refused_by_lock(const MessageEntry& reply) {
    if (reply.error == MessageErrorType::ObjectLockedError) return true;
    if (reply.error != MessageErrorType::InvalidOperation) return false;
    const auto* msg = reply.find("errorstring");
    return msg && read_string(*msg).find("monitor locked") != std::string_view::npos;
}

void PassthroughSessions::stop_as_lock_holder(std::uint32_t endpoint, MessageEntry stop,
                                              std::function<void(Result<MessageEntry>)> answer, Result<MessageEntry> refused) {
    std::shared_ptr<RawClient> holder;
    std::uint32_t holder_endpoint = 0;
    {
        std::lock_guard lock(mutex_);
        for (const auto& l : locks_) {
            if (l.endpoint == endpoint) continue;
            // Stops are on the root object, which only a lock on the root binds (gateway naming on both).
            if (l.path != stop.service_path) continue;
            auto it = links_.find(l.endpoint);
            if (it == links_.end() || it->second.lost || !it->second.client || !it->second.client->is_open()) continue;
            holder = it->second.client;
            holder_endpoint = l.endpoint;
            break;
        }
    }
    if (!holder) return answer(std::move(refused));
    forward(holder_endpoint, holder, std::move(stop), [answer = std::move(answer)](Result<MessageEntry> r) { answer(std::move(r)); });
}

void PassthroughSessions::request(std::uint32_t endpoint, MessageEntry entry, std::function<void(Result<MessageEntry>)> done) {
    auto client = open_client(endpoint);
    if (!client) {
        done(fail(session_gone()));
        return;
    }
    forward(endpoint, client, std::move(entry), std::move(done));
}

void PassthroughSessions::forward(std::uint32_t endpoint, const std::shared_ptr<RawClient>& client, MessageEntry&& entry,
                                  std::function<void(Result<MessageEntry>)> done) {
    const std::string downstream_path = entry.service_path;
    entry.service_path = to_upstream(entry.service_path);
    const std::string op = entry.entry_type == MessageEntryType::ClientSessionOpReq ? entry.member_name : std::string();
    if (auto k = counters_.lock()) k->requests.fetch_add(1);
    const auto start = std::chrono::steady_clock::now();
    std::weak_ptr<PassthroughSessions> weak = weak_from_this();
    // MonitorEnter waits on the device up to its own 5 s "Continue" answer; the default timeout covers it.
    client->request(std::move(entry), [weak, done = std::move(done), op, endpoint, downstream_path, start](Result<MessageEntry> r) {
        auto self = weak.lock();
        if (auto k = self ? self->counters_.lock() : nullptr) {
            k->observe_latency(std::chrono::steady_clock::now() - start);
            if (!r || r->error != MessageErrorType::None) k->request_errors.fetch_add(1);
        }
        if (r && self) {
            r->service_path = self->to_downstream(r->service_path);
            if (!op.empty() && r->error == MessageErrorType::None && is_lock_op(op)) {
                self->note_lock_reply(endpoint, op, downstream_path, *r);
                self->changed();
            }
        }
        done(std::move(r));
    });
}

void PassthroughSessions::note_lock_reply(std::uint32_t endpoint, const std::string& op, const std::string& path,
                                          const MessageEntry& reply) {
    std::lock_guard lock(mutex_);
    auto it = links_.find(endpoint);
    if (it == links_.end()) return;
    const std::string& user = it->second.username;
    auto erase_at = [&](bool monitor) {
        std::erase_if(locks_, [&](const DeviceLockInfo& l) {
            return l.path == path && (l.kind == "monitor") == monitor && (!monitor || l.endpoint == endpoint);
        });
    };
    if (op == "RequestObjectLock" || op == "RequestClientObjectLock") {
        erase_at(false);
        locks_.push_back(DeviceLockInfo{path, user, op == "RequestObjectLock" ? "user" : "client", endpoint});
    } else if (op == "ReleaseObjectLock" || op == "ReleaseClientObjectLock") {
        erase_at(false);
    } else if (op == "MonitorEnter" || op == "MonitorContinueEnter") {
        if (reply_return(reply) == "OK") {
            erase_at(true);
            locks_.push_back(DeviceLockInfo{path, user, "monitor", endpoint});
        }
    } else if (op == "MonitorExit") {
        erase_at(true);
    }
}

void PassthroughSessions::from_device(std::uint32_t endpoint, MessageEntry&& entry) {
    SessionRef session;
    std::shared_ptr<RawClient> client, api_client;
    std::shared_ptr<const DeliveryCheck> check;
    std::shared_ptr<const ApiHandlers> api;
    {
        std::lock_guard lock(mutex_);
        check = delivery_check_;
        auto it = links_.find(endpoint);
        if (it == links_.end()) return;
        if (it->second.api) {
            api_client = it->second.client;
            api = it->second.api_handlers;
        } else if (!it->second.attached) {
            // Between the connect's answer and the downstream session's opening: held (bounded).
            if (it->second.early.size() < 256) it->second.early.push_back(std::move(entry));
            return;
        } else {
            session = it->second.session;
            client = it->second.client;
        }
    }
    if (api_client) {
        // A JSON API session has nobody to run a callback: the device gets an error instead of a wait.
        if (entry.entry_type == MessageEntryType::CallbackCallReq) {
            api_client->send(relayed_reply(
                reply_to(entry), fail(MessageErrorType::InvalidOperation,
                                   "callback \"" + entry.member_name + "\": this session is a JSON API client's, which has no callbacks")));
            return;
        }
        if (!api || !api->on_entry) return;
        if (auto k = counters_.lock()) {
            if (entry.entry_type == MessageEntryType::EventReq) k->events.fetch_add(1);
            if (entry.entry_type == MessageEntryType::WirePacket) k->wire_packets_in.fetch_add(1);
            if (entry.entry_type == MessageEntryType::PipePacket) k->pipe_packets.fetch_add(1);
        }
        entry.service_path = to_downstream(entry.service_path);
        api->on_entry(std::move(entry));
        return;
    }
    deliver(session, client, check, std::move(entry));
}

void PassthroughSessions::deliver(const SessionRef& session, const std::shared_ptr<RawClient>& client,
                                  const std::shared_ptr<const DeliveryCheck>& check, MessageEntry&& entry) {
    entry.service_path = to_downstream(entry.service_path);
    const auto counters = counters_.lock();
    const auto type = entry.entry_type;
    const bool checked = type == MessageEntryType::CallbackCallReq || type == MessageEntryType::WirePacket ||
                         type == MessageEntryType::EventReq || type == MessageEntryType::PipePacket;
    if (check && checked && !(*check)(session, entry)) {
        // The client's roles do not let it receive this: as on a shared device, packets and events are
        // not sent to it, and the device's callback call gets an error instead of a client's answer.
        if (type == MessageEntryType::CallbackCallReq && client) {
            MessageEntry reply_header = reply_to(entry);
            reply_header.service_path = to_upstream(entry.service_path);
            client->send(relayed_reply(reply_header, fail(MessageErrorType::PermissionDenied,
                                                          "the client's role may not call " + entry.member_name + " (gateway.auth)")));
        }
        return;
    }
    switch (type) {
        case MessageEntryType::CallbackCallReq: {
            // The device calls exactly this client: it is the only one on this upstream session.
            if (counters) counters->callbacks.fetch_add(1);
            MessageEntry reply_header = reply_to(entry);
            reply_header.service_path = to_upstream(entry.service_path);
            std::weak_ptr<RawClient> weak_client = client;
            session.request(std::move(entry), [weak_client, reply_header](Result<MessageEntry> r) mutable {
                auto c = weak_client.lock();
                if (!c) return;
                c->send(relayed_reply(reply_header, std::move(r)));
            });
            return;
        }
        case MessageEntryType::WirePacket:
            if (counters) counters->wire_packets_out.fetch_add(1);
            (void)session.send_wire_packet(std::move(entry));
            return;
        case MessageEntryType::EventReq:
            if (counters) counters->events.fetch_add(1);
            (void)session.send(std::move(entry));
            return;
        case MessageEntryType::PipePacket:
            if (counters) counters->pipe_packets.fetch_add(1);
            if (!session.send(std::move(entry)) && counters) counters->pipe_drops.fetch_add(1);
            return;
        default: (void)session.send(std::move(entry)); return;
    }
}

void PassthroughSessions::upstream_closed(std::uint32_t endpoint, const RRError& error) {
    // The device ended this client's session (or went away): its locks are gone on the device too.
    // The downstream session stays open; its requests fail with ConnectionError from now on.
    std::shared_ptr<const ApiHandlers> api;
    {
        std::lock_guard lock(mutex_);
        auto it = links_.find(endpoint);
        if (it == links_.end() || !it->second.client) return;
        it->second.lost = true;
        api = it->second.api_handlers;
        forget_locks_of(endpoint, it->second.username);
    }
    changed();
    // A JSON API session's subscriptions end with it (the client is told, and may device_login again).
    if (api && api->on_lost) api->on_lost(error.message.empty() ? session_gone() : make_error(MessageErrorType::ConnectionError,
                                                                                             "the device \"" + settings_.device_name +
                                                                                                 "\" closed this client's session: " +
                                                                                                 error.message));
}

}  // namespace rr::server::gateway
