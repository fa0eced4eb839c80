#include "server/gateway/motion_guard.hpp"

#include <ctime>

#include "base/message/error_entry.hpp"
#include "core/session/elements.hpp"

namespace rr::server::gateway {
namespace {

std::int32_t index_of(const MessageEntry& e) {
    std::int32_t idx = -1;
    if (const auto* el = e.find("index")) (void)read_scalar(*el, idx);
    return idx;
}

bool answered_ok(const Result<MessageEntry>& reply) { return reply && reply->error == MessageErrorType::None; }

std::string seconds_text(double s) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g s", s);
    return buf;
}

}  // namespace

MotionGuard::MotionGuard(boost::asio::any_io_executor executor, std::string device, MotionSafety settings, DeviceRequest request)
    : device_(std::move(device)),
      settings_(std::move(settings)),
      request_(std::move(request)),
      timer_(executor),
      holds_(settings_.hold_to_run_max) {}

MotionGuard::~MotionGuard() {
    std::lock_guard lock(mutex_);
    timer_.cancel();
}

void MotionGuard::set_root(const ObjectTypeInfo& root, const DeviceTypes* types) {
    auto rules = std::make_shared<const MotionRules>(MotionRules::compile(settings_, root, types));
    std::lock_guard lock(mutex_);
    rules_ = std::move(rules);
}

std::shared_ptr<const MotionRules> MotionGuard::rules() const {
    std::lock_guard lock(mutex_);
    return rules_;
}

void MotionGuard::set_event_listener(std::function<void(const std::string&)> listener) {
    std::lock_guard lock(mutex_);
    listener_ = std::move(listener);
}

void MotionGuard::emit(const std::string& message) const {
    std::function<void(const std::string&)> listener;
    {
        std::lock_guard lock(mutex_);
        listener = listener_;
    }
    if (listener) listener(message);
}

std::string MotionGuard::wall_clock_text() {
    const auto now = std::chrono::system_clock::now();
    const std::time_t t = std::chrono::system_clock::to_time_t(now);
    std::tm tm{};
    gmtime_r(&t, &tm);
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
    char buf[40];
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900, tm.tm_mon + 1, tm.tm_mday,
                  tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(ms));
    return buf;
}

Result<MotionGuard::Ticket> MotionGuard::admit(const MotionClient& client, MessageEntry& entry) {
    if (entry.service_path != device_) return Ticket{};
    std::vector<std::function<void()>> after;
    std::string note;
    std::string taken;
    Result<Ticket> out = Ticket{};
    {
        std::lock_guard lock(mutex_);
        const auto rules = rules_;
        if (!rules || rules->empty()) return Ticket{};
        const auto now = Clock::now();
        const auto take = [&]() {
            const bool held = holds_.holder(now) != nullptr;
            auto r = holds_.take(client, now, wall_clock_text(), device_);
            // A hold starting (again): shows when a holder's hold lapsed and another client took over.
            if (r && !held) taken = entry.member_name + ": motion of " + device_ + " taken by " + client.who();
            return r;
        };
        const std::string& member = entry.member_name;
        switch (entry.entry_type) {
            case MessageEntryType::FunctionCallReq: {
                if (rules->stop_function(member)) {
                    holds_.stopped();
                    motions_.clear();
                    out = Ticket{Ticket::Kind::stop};
                    break;
                }
                if (const auto* h = rules->hold_to_run(member)) {
                    const auto asked = [&]() -> std::optional<double> {
                        for (const auto& e : entry.elements)
                            if (!e.number && e.name == h->timeout_arg) return scalar_number(e);
                        return std::nullopt;
                    }();
                    auto seconds = clamp_timeout(entry, *h, rules->bound());
                    if (!seconds) {
                        out = seconds.take_error();
                        break;
                    }
                    if (auto ok = take(); !ok) {
                        out = ok.take_error();
                        break;
                    }
                    const auto before =
                        holds_.timed(now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(*seconds)));
                    if (asked && *asked * h->unit_s != *seconds)
                        note = member + " from " + client.who() + ": timeout " + seconds_text(*asked * h->unit_s) +
                               " clamped to " + seconds_text(*seconds) + " (safety.hold_to_run_max_s)";
                    Ticket t{Ticket::Kind::timed};
                    t.timed_before = before;
                    out = t;
                    break;
                }
                if (const auto* u = rules->untimed(member)) {
                    if (auto ok = take(); !ok) {
                        out = ok.take_error();
                        break;
                    }
                    Ticket t;
                    t.kind = u->wait_arg.empty() ? Ticket::Kind::generator : Ticket::Kind::untimed;
                    t.waits = !u->wait_arg.empty() && bool_argument(entry, u->wait_arg).value_or(false);
                    t.token = holds_.begin_untimed(client.owner_key(), member);
                    motions_[t.token] = Motion{client.key, -1, member, client.device_session};
                    out = t;
                    break;
                }
                break;
            }
            case MessageEntryType::GeneratorNextReq: {
                if (!rules->untimed(member)) break;
                Ticket t;
                t.kind = Ticket::Kind::generator_next;
                t.generator = index_of(entry);
                t.closes = entry.error != MessageErrorType::None;
                out = t;
                break;
            }
            case MessageEntryType::PropertySetReq: {
                const auto* v = entry.find("value");
                if (v && rules->stop_property(member, *v)) {
                    holds_.stopped();
                    motions_.clear();
                    out = Ticket{Ticket::Kind::stop};
                }
                break;
            }
            case MessageEntryType::WirePacket: {
                if (!rules->stream(member)) break;
                if (auto ok = take(); !ok) {
                    out = ok.take_error();
                    break;
                }
                holds_.stream_packet(member, now);
                break;
            }
            case MessageEntryType::WireConnectReq: {
                if (!rules->stream(member)) break;
                const auto* h = holds_.holder(now);
                if (h && h->key != client.key)
                    if (auto r = take(); !r) out = r.take_error();
                break;
            }
            default: break;
        }
        if (!out && entry.entry_type != MessageEntryType::WirePacket)
            note = std::string(member) + " from " + client.who() + " refused: " + out.error().message;
        update_probe(after);
        arm_timer();
    }
    for (auto& f : after) f();
    if (!taken.empty()) emit(taken);
    if (!note.empty()) emit(note);
    return out;
}

void MotionGuard::on_reply(const MotionClient& client, const Ticket& ticket, const Result<MessageEntry>& reply) {
    std::vector<std::function<void()>> after;
    {
        std::lock_guard lock(mutex_);
        auto end = [&](std::uint64_t token) {
            holds_.end_untimed(token);
            motions_.erase(token);
        };
        switch (ticket.kind) {
            case Ticket::Kind::timed:
                // Refused (a lock, the device): the call moves nothing and holds nothing.
                if (!answered_ok(reply)) holds_.undo_timed(client.key, ticket.timed_before, Clock::now());
                break;
            case Ticket::Kind::untimed:
                // A call that waits is over with its answer; one that does not keeps moving until a stop
                // or its client's end. An error: nothing started.
                if (!answered_ok(reply) || ticket.waits) end(ticket.token);
                break;
            case Ticket::Kind::generator: {
                if (!answered_ok(reply)) {
                    end(ticket.token);
                    break;
                }
                auto it = motions_.find(ticket.token);
                if (it != motions_.end()) it->second.index = index_of(*reply);
                break;
            }
            case Ticket::Kind::generator_next: {
                // StopIteration, any other error and the client's own close or abort end the generator.
                if (!ticket.closes && answered_ok(reply)) break;
                for (auto it = motions_.begin(); it != motions_.end(); ++it)
                    if (it->second.key == client.key && it->second.index == ticket.generator && ticket.generator >= 0) {
                        holds_.end_untimed(it->first);
                        motions_.erase(it);
                        break;
                    }
                break;
            }
            default: return;
        }
        update_probe(after);
        arm_timer();
    }
    for (auto& f : after) f();
}

bool MotionGuard::concerns(const MessageEntry& entry) const {
    switch (entry.entry_type) {
        case MessageEntryType::FunctionCallReq:
        case MessageEntryType::GeneratorNextReq:
        case MessageEntryType::PropertySetReq:
        case MessageEntryType::WirePacket:
        case MessageEntryType::WireConnectReq: break;
        default: return false;
    }
    if (entry.service_path != device_) return false;
    const auto rules = this->rules();
    return rules && rules->guards(entry.member_name);
}

bool MotionGuard::is_stop(const MessageEntry& entry) const {
    if (entry.service_path != device_) return false;
    const auto rules = this->rules();
    if (!rules) return false;
    if (entry.entry_type == MessageEntryType::FunctionCallReq) return rules->stop_function(entry.member_name);
    if (entry.entry_type == MessageEntryType::PropertySetReq) {
        const auto* v = entry.find("value");
        return v && rules->stop_property(entry.member_name, *v);
    }
    return false;
}

void MotionGuard::client_gone(const std::string& owner, std::function<void()> done) {
    std::vector<std::function<void()>> after;
    std::vector<Motion> aborts;
    std::uint32_t session = 0;
    bool stop = false;
    {
        std::lock_guard lock(mutex_);
        auto gone = holds_.gone(owner, Clock::now());
        for (auto token : gone.tokens) {
            auto it = motions_.find(token);
            if (it == motions_.end()) continue;
            session = it->second.session;
            if (it->second.index >= 0) aborts.push_back(it->second);
            motions_.erase(it);
        }
        if (gone.stop && !session && probing_ && probing_->owner_key() == owner) session = probing_->device_session;
        stop = gone.stop;
        update_probe(after);
        arm_timer();
    }
    for (auto& f : after) f();
    if (!stop) {
        if (done) done();
        return;
    }
    stop_device(std::move(aborts), session, "the client that started it went away", std::move(done));
}

std::optional<MotionGuard::HolderInfo> MotionGuard::holder() const {
    std::lock_guard lock(mutex_);
    const auto* h = holds_.holder(Clock::now());
    if (!h) return std::nullopt;
    return HolderInfo{h->who(), h->user, holds_.since()};
}

std::uint64_t MotionGuard::stops_sent() const {
    std::lock_guard lock(mutex_);
    return stops_sent_;
}

void MotionGuard::update_probe(std::vector<std::function<void()>>& after) {
    const MotionClient* want = holds_.probed();
    const std::string want_key = want ? want->key : std::string();
    const std::string have_key = probing_ ? probing_->key : std::string();
    if (want_key == have_key) return;
    if (probing_ && probing_->liveness) after.push_back([f = probing_->liveness] { f(std::nullopt); });
    probing_.reset();
    if (!want) return;
    probing_ = *want;
    if (want->liveness) after.push_back([f = want->liveness, b = settings_.hold_to_run_max] { f(b); });
}

void MotionGuard::arm_timer() {
    const auto next = holds_.next_deadline();
    if (!next) return;
    if (timer_at_ && *timer_at_ <= *next) return;
    timer_at_ = *next;
    timer_.expires_at(*next);
    std::weak_ptr<MotionGuard> weak = weak_from_this();
    timer_.async_wait([weak](boost::system::error_code ec) {
        if (ec) return;  // re-armed (an earlier deadline) or stopped
        if (auto self = weak.lock()) self->on_timer();
    });
}

void MotionGuard::on_timer() {
    std::vector<std::function<void()>> after;
    std::vector<std::string> silent;
    std::uint32_t session = 0;
    std::string who;
    {
        std::lock_guard lock(mutex_);
        timer_at_.reset();
        if (probing_) {
            session = probing_->device_session;
            who = probing_->who();
        }
        silent = holds_.expire(Clock::now());
        update_probe(after);
        arm_timer();
    }
    for (auto& f : after) f();
    if (silent.empty()) return;
    stop_device({}, session, "command stream " + silent.front() + " of " + who + " silent for " +
                                 seconds_text(std::chrono::duration<double>(settings_.hold_to_run_max).count()),
                {});
}

void MotionGuard::stop_device(std::vector<Motion> aborts, std::uint32_t session, std::string why, std::function<void()> done) {
    const auto rules = this->rules();
    std::vector<std::pair<MessageEntry, std::uint32_t>> requests;
    for (const auto& g : aborts) {
        MessageEntry e;
        e.entry_type = MessageEntryType::GeneratorNextReq;
        e.service_path = device_;
        e.member_name = g.member;
        set_entry_error(e, make_error(MessageErrorType::OperationAborted, "the client that started it went away (rr-gateway)"));
        e.elements.push_back(make_scalar_element<std::int32_t>("index", g.index));
        requests.emplace_back(std::move(e), g.session);
    }
    if (rules)
        for (auto& stop : rules->stop_requests(device_)) {
            if (session) requests.emplace_back(stop, session);
            requests.emplace_back(std::move(stop), 0);
        }
    {
        std::lock_guard lock(mutex_);
        ++stops_sent_;
    }
    emit("motion of " + device_ + " ended by the gateway: " + why);
    // `done` once every request was answered, or after 2 s (a device that does not answer).
    struct Pending {
        std::mutex mutex;
        std::size_t left = 0;
        std::function<void()> done;
        void finish() {
            std::function<void()> d;
            {
                std::lock_guard lock(mutex);
                d.swap(done);
            }
            if (d) d();
        }
    };
    auto pending = std::make_shared<Pending>();
    pending->left = requests.size();
    pending->done = std::move(done);
    if (requests.empty()) return pending->finish();
    auto timer = std::make_shared<boost::asio::steady_timer>(timer_.get_executor(), std::chrono::seconds(2));
    timer->async_wait([pending, timer](boost::system::error_code) { pending->finish(); });
    for (auto& [e, s] : requests)
        request_(std::move(e), s, [pending, timer](Result<MessageEntry>) {
            bool last = false;
            {
                std::lock_guard lock(pending->mutex);
                last = pending->left > 0 && --pending->left == 0;
            }
            if (last) {
                timer->cancel();
                pending->finish();
            }
        });
}

}  // namespace rr::server::gateway
