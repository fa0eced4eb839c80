// A device's clock as Foxglove's time (foxglove_clock.hpp).
#include "server/foxglove/foxglove_clock.hpp"

#include <algorithm>

#include "server/foxglove/foxglove_connection.hpp"

namespace rr::server::foxglove {

namespace {

constexpr std::string_view kDeviceClockService = "com.robotraconteur.device.clock";
constexpr std::string_view kDateTimeService = "com.robotraconteur.datetime";
constexpr std::string_view kClockObject = "com.robotraconteur.datetime.clock.Clock";

// {"seconds", "nanoseconds"} of a DateTimeUTC as JSON (a pod: one object; an array of one tolerated).
std::optional<std::uint64_t> utc_ns(const nlohmann::json& v) {
    const nlohmann::json& o = v.is_array() && v.size() == 1 ? v[0] : v;
    if (!o.is_object()) return std::nullopt;
    auto s = o.find("seconds");
    auto n = o.find("nanoseconds");
    if (s == o.end() || n == o.end() || !s->is_number_integer() || !n->is_number_integer()) return std::nullopt;
    const auto seconds = s->get<std::int64_t>();
    const auto nanos = n->get<std::int64_t>();
    // Before the epoch (or a clock without UTC: zero) or past year 2500: not a time Foxglove can show.
    if (seconds <= 0 || seconds > 16'725'225'600 || nanos < 0 || nanos >= 1'000'000'000) return std::nullopt;
    return static_cast<std::uint64_t>(seconds) * 1'000'000'000u + static_cast<std::uint64_t>(nanos);
}

}  // namespace

std::optional<ClockWireKind> clock_wire_kind(const LiveMember& m) {
    if (m.kind != LiveKind::wire || m.image || !m.target || !m.target->member) return std::nullopt;
    const auto& member = *m.target->member;
    if (member.direction() == robdef::MemberDirection::writeonly) return std::nullopt;
    const auto& type = member.type;
    if (type.base != DataTypes::namedtype_t || type.array != robdef::ArrayKind::none || type.container != robdef::ContainerKind::none)
        return std::nullopt;
    auto ref = m.target->types->set().find(type.type_name, m.target->context());
    if (!ref || !ref.entry) return std::nullopt;
    if (ref.service->name == kDeviceClockService && ref.entry->name == "DeviceTime") return ClockWireKind::device_time;
    if (ref.service->name == kDateTimeService && ref.entry->name == "DateTimeUTC") return ClockWireKind::date_time_utc;
    return std::nullopt;
}

const LiveMember* find_clock_wire(const std::vector<LiveMember>& members) {
    const LiveMember* utc = nullptr;
    for (const auto& m : members) {
        if (!m.object.empty()) continue;
        auto kind = clock_wire_kind(m);
        if (kind == ClockWireKind::device_time) return &m;
        if (kind == ClockWireKind::date_time_utc && !utc) utc = &m;
    }
    return utc;
}

bool is_clock_device(const gateway::DeviceMirror& device) { return device.object_type() == kClockObject; }

std::optional<std::uint64_t> clock_time_ns(const gateway::JsonApi& api, const LiveMember& member, ClockWireKind kind,
                                           const MessageEntry& packet) {
    const MessageElement* el = packet.find("packet");
    if (!el) return std::nullopt;
    auto r = api.element_json(*el, member.target->member->type, *member.target);
    if (!r) return std::nullopt;
    if (kind == ClockWireKind::date_time_utc) return utc_ns(r.value);
    const nlohmann::json& o = r.value.is_array() && r.value.size() == 1 ? r.value[0] : r.value;
    if (!o.is_object() || !o.contains("device_utc")) return std::nullopt;
    return utc_ns(o["device_utc"]);
}

FoxgloveClock::FoxgloveClock(std::shared_ptr<gateway::JsonApi> api, std::chrono::milliseconds interval,
                             std::function<void()> on_time)
    : api_(std::move(api)), interval_(interval), on_time_(std::move(on_time)) {}

FoxgloveClock::~FoxgloveClock() {
    std::vector<std::pair<std::shared_ptr<gateway::DeviceMirror>, std::uint64_t>> unsubscribe;
    {
        std::lock_guard lock(mutex_);
        stop_locked(unsubscribe);
    }
    for (auto& [d, id] : unsubscribe) d->unsubscribe(id);
}

void FoxgloveClock::stop_locked(std::vector<std::pair<std::shared_ptr<gateway::DeviceMirror>, std::uint64_t>>& to_unsubscribe) {
    if (member_ && upstream_known_) to_unsubscribe.emplace_back(member_->target->device, upstream_);
    member_.reset();
    upstream_known_ = false;
    ++serial_;
}

void FoxgloveClock::follow(const LiveMember& member, ClockWireKind kind) {
    std::vector<std::pair<std::shared_ptr<gateway::DeviceMirror>, std::uint64_t>> unsubscribe;
    std::uint64_t serial = 0;
    auto followed = std::make_shared<const LiveMember>(member);
    {
        std::lock_guard lock(mutex_);
        stop_locked(unsubscribe);
        member_ = followed;
        kind_ = kind;
        serial = serial_;
    }
    for (auto& [d, id] : unsubscribe) d->unsubscribe(id);
    std::weak_ptr<FoxgloveClock> weak = weak_from_this();
    const auto& t = *followed->target;
    // The gateway's shared upstream subscription of the wire (one for every client of it).
    const std::uint64_t upstream = t.device->subscribe(
        t.path, t.member->name, /*is_wire=*/true,
        [weak, serial](const gateway::SharedEntryPtr& e) {
            if (auto self = weak.lock()) self->on_packet(serial, e);
        },
        [](Result<void>) {});  // a refused subscription leaves the clock silent; the next connect tries again
    bool drop = false;
    {
        std::lock_guard lock(mutex_);
        if (serial != serial_) {
            drop = true;
        } else {
            upstream_ = upstream;
            upstream_known_ = true;
        }
    }
    if (drop) t.device->unsubscribe(upstream);
}

void FoxgloveClock::device_gone(const std::string& device) {
    std::vector<std::pair<std::shared_ptr<gateway::DeviceMirror>, std::uint64_t>> unsubscribe;
    {
        std::lock_guard lock(mutex_);
        if (!member_ || member_->target->device->config().name != device) return;
        stop_locked(unsubscribe);
    }
    for (auto& [d, id] : unsubscribe) d->unsubscribe(id);
}

bool FoxgloveClock::has_time() const {
    std::lock_guard lock(mutex_);
    return last_time_.has_value();
}

std::string FoxgloveClock::device() const {
    std::lock_guard lock(mutex_);
    return member_ ? member_->target->device->config().name : std::string();
}

std::uint64_t FoxgloveClock::now_ns() {
    std::lock_guard lock(mutex_);
    std::uint64_t t = 0;
    if (last_time_) {
        const auto elapsed = std::chrono::steady_clock::now() - last_arrival_;
        t = *last_time_ + static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(elapsed).count());
    } else {
        t = foxglove::now_ns();
    }
    last_returned_ = std::max(last_returned_, t);
    return last_returned_;
}

void FoxgloveClock::on_packet(std::uint64_t serial, const gateway::SharedEntryPtr& e) {
    if (e->entry().entry_type != MessageEntryType::WirePacket) return;
    std::shared_ptr<const LiveMember> member;
    ClockWireKind kind{};
    {
        std::lock_guard lock(mutex_);
        if (serial != serial_ || !member_) return;
        member = member_;
        kind = kind_;
    }
    auto t = clock_time_ns(*api_, *member, kind, e->entry());
    if (!t) return;
    bool forward = false;
    {
        std::lock_guard lock(mutex_);
        if (serial != serial_) return;
        const auto now = std::chrono::steady_clock::now();
        // A clock that went back itself (a simulation restarted): the times sent follow it. A clock that
        // went on: never before a time handed out already (receive times run on between its ticks, and
        // a tick's delay on its way here would otherwise look like a step back).
        if (last_time_ && *t < *last_time_)
            last_returned_ = *t;
        else
            last_returned_ = std::max(last_returned_, *t);
        last_time_ = *t;
        last_arrival_ = now;
        if (now - last_forwarded_ >= interval_) {
            last_forwarded_ = now;
            forward = true;
        }
    }
    if (forward && on_time_) on_time_();
}

}  // namespace rr::server::foxglove
