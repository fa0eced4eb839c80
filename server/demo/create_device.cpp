#include "server/demo/create_device.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <boost/asio/post.hpp>

#include "robdef/builtin/experimental_create.hpp"

namespace rr::server::demo {

namespace asio = boost::asio;
using namespace std::chrono_literals;

namespace {

std::int32_t round_i32(double v) {
    if (!(v == v)) return 0;
    const double r = std::round(v);
    if (r >= static_cast<double>(std::numeric_limits<std::int32_t>::max())) return std::numeric_limits<std::int32_t>::max();
    if (r <= static_cast<double>(std::numeric_limits<std::int32_t>::min())) return std::numeric_limits<std::int32_t>::min();
    return static_cast<std::int32_t>(r);
}

template <class T>
void put_le(std::uint8_t* p, T v) {
    using U = std::make_unsigned_t<T>;
    const U u = static_cast<U>(v);
    for (std::size_t i = 0; i < sizeof(T); ++i) p[i] = static_cast<std::uint8_t>(u >> (8 * i));
}

}  // namespace

std::array<std::uint8_t, kSensorDataSize> encode_sensor_data(const CreateState& s, std::uint16_t sequence,
                                                             const std::vector<std::uint8_t>& last_song,
                                                             bool have_song) {
    std::array<std::uint8_t, kSensorDataSize> d{};
    d[0] = 1;
    d[1] = s.bumpers;
    put_le<std::uint16_t>(&d[2], sequence);
    put_le<std::int32_t>(&d[4], round_i32(s.distance_mm));
    put_le<std::int32_t>(&d[8], round_i32(s.angle_deg));
    put_le<std::int32_t>(&d[12], round_i32(s.x_mm));
    put_le<std::int32_t>(&d[16], round_i32(s.y_mm));
    double deg = s.heading_rad * 180.0 / 3.14159265358979323846;
    std::int32_t centi = round_i32(deg * 100.0) % 36000;
    if (centi < 0) centi += 36000;
    put_le<std::int32_t>(&d[20], centi);
    put_le<std::int16_t>(&d[24], s.velocity);
    put_le<std::int16_t>(&d[26], s.radius);
    const double ms = std::floor(s.time_s * 1000.0);
    put_le<std::uint32_t>(&d[28], static_cast<std::uint32_t>(static_cast<std::uint64_t>(std::max(0.0, ms)) & 0xFFFFFFFFu));
    put_le<std::uint16_t>(&d[32], static_cast<std::uint16_t>(s.bumps & 0xFFFFu));
    d[34] = have_song ? static_cast<std::uint8_t>(std::min<std::size_t>(last_song.size(), 255)) : 0;
    d[35] = have_song && !last_song.empty() ? last_song[0] : 0;
    return d;
}

CreateDevice::CreateDevice(CreateDeviceOptions options) : options_(options), sim_(options.geometry) {}

CreateDevice::~CreateDevice() = default;

Result<std::shared_ptr<CreateDevice>> CreateDevice::create(CreateDeviceOptions options) {
    if (options.step_period <= 0ms || options.packet_period <= 0ms || options.play_period < 0ms)
        return fail(MessageErrorType::InvalidArgument, "create device: periods must be positive");
    auto types = ServiceTypes::create({std::string(robdef::experimental_create_robdef())});
    if (!types) return types.take_error();
    std::shared_ptr<CreateDevice> device(new CreateDevice(options));
    auto object = ServiceObject::create(*types, robdef::kExperimentalCreateObjectType);
    if (!object) return object.take_error();
    device->object_ = *object;
    if (auto r = device->attach_handlers(); !r) return r.take_error();
    return device;
}

Result<void> CreateDevice::attach_handlers() {
    std::weak_ptr<CreateDevice> weak = weak_from_this();
    auto gone = [] { return fail(MessageErrorType::ServiceNotFound, "the create device has shut down"); };
    auto& o = *object_;

    auto r = o.set_function("Drive", [weak, gone](const SessionRef&, std::vector<Value> args) -> Result<Value> {
        auto self = weak.lock();
        if (!self) return gone();
        auto v = args.at(0).as<std::int16_t>();
        if (!v) return v.take_error();
        auto rad = args.at(1).as<std::int16_t>();
        if (!rad) return rad.take_error();
        if (auto d = self->drive(*v, *rad); !d) return d.take_error();
        return Value();
    });
    if (!r) return r;
    r = o.set_function("StartStreaming", [weak, gone](const SessionRef& session, std::vector<Value>) -> Result<Value> {
        auto self = weak.lock();
        if (!self) return gone();
        self->start_streaming(session);
        return Value();
    });
    if (!r) return r;
    r = o.set_function("StopStreaming", [weak, gone](const SessionRef& session, std::vector<Value>) -> Result<Value> {
        auto self = weak.lock();
        if (!self) return gone();
        self->stop_streaming(session);
        return Value();
    });
    if (!r) return r;

    auto property = [&](const char* name, auto get) -> Result<void> {
        return o.set_property_handlers(name, [weak, gone, get](const SessionRef&) -> Result<Value> {
            auto self = weak.lock();
            if (!self) return gone();
            return get(self->state());
        });
    };
    r = property("DistanceTraveled",
                 [](const CreateState& s) { return Value::scalar<std::int32_t>(round_i32(s.distance_mm)); });
    if (!r) return r;
    r = property("AngleTraveled", [](const CreateState& s) { return Value::scalar<std::int32_t>(round_i32(s.angle_deg)); });
    if (!r) return r;
    r = property("Bumpers", [](const CreateState& s) { return Value::scalar<std::uint8_t>(s.bumpers); });
    if (!r) return r;

    auto wire = o.wire("packets");
    if (!wire) return wire.take_error();
    packets_ = *wire;
    auto cb = o.callback("play_callback");
    if (!cb) return cb.take_error();
    play_callback_ = *cb;
    // A value from the start: a client connecting the wire always gets one.
    return packets_->set_out_value(sensor_packet());
}

Result<void> CreateDevice::drive(std::int16_t velocity, std::int16_t radius) {
    std::lock_guard lock(mutex_);
    return sim_.drive(velocity, radius);
}

void CreateDevice::place(double x_mm, double y_mm, double heading_deg) {
    std::lock_guard lock(mutex_);
    sim_.place(x_mm, y_mm, heading_deg);
}

void CreateDevice::start_streaming(const SessionRef& session) {
    std::lock_guard lock(mutex_);
    std::erase(streamers_, session);
    streamers_.push_back(session);
    packet_due_ = options_.packet_period;  // a packet with the next step
}

void CreateDevice::stop_streaming(const SessionRef& session) {
    std::lock_guard lock(mutex_);
    std::erase(streamers_, session);
    if (streamers_.empty()) {
        packet_due_ = 0ns;
        play_due_ = 0ns;
    }
}

CreateState CreateDevice::state() const {
    std::lock_guard lock(mutex_);
    return sim_.state();
}

bool CreateDevice::streaming() const {
    std::lock_guard lock(mutex_);
    return std::any_of(streamers_.begin(), streamers_.end(), [](const SessionRef& s) { return s.alive(); });
}

PlayStats CreateDevice::play_stats() const {
    std::lock_guard lock(mutex_);
    return play_stats_;
}

std::uint16_t CreateDevice::packet_sequence() const {
    std::lock_guard lock(mutex_);
    return sequence_;
}

Value CreateDevice::sensor_packet() const {
    std::lock_guard lock(mutex_);
    return make_packet_locked(sequence_);
}

Value CreateDevice::make_packet_locked(std::uint16_t sequence) const {
    const auto data = encode_sensor_data(sim_.state(), sequence, play_stats_.last_song, play_stats_.replies > 0);
    Structure s;
    s.type_name = std::string(robdef::kExperimentalCreateSensorPacket);
    s.set("ID", Value::scalar<std::uint8_t>(kSensorPacketId));
    s.set("Data", Value(NumericArray::from<std::uint8_t>(std::span<const std::uint8_t>(data.data(), data.size()))));
    return Value(std::move(s));
}

void CreateDevice::advance(std::chrono::nanoseconds dt) {
    dt = std::clamp<std::chrono::nanoseconds>(dt, 0ns, 1s);
    std::uint32_t bumps = 0;
    std::optional<Value> packet;
    SessionRef play_target;
    bool play = false;
    std::int32_t play_distance = 0, play_angle = 0;
    {
        std::lock_guard lock(mutex_);
        std::erase_if(streamers_, [](const SessionRef& s) { return !s.alive(); });
        const bool streaming = !streamers_.empty();
        const std::chrono::nanoseconds step = options_.step_period;
        const double step_s = std::chrono::duration<double>(step).count();
        bool packet_due = false;
        pending_ += dt;
        while (pending_ >= step) {
            pending_ -= step;
            if (sim_.step(step_s)) ++bumps;
            if (streaming) {
                packet_due_ += step;
                if (packet_due_ >= options_.packet_period) {
                    packet_due_ -= options_.packet_period;
                    if (packet_due_ >= options_.packet_period) packet_due_ = 0ns;  // catching up: one packet
                    packet_due = true;
                }
                if (options_.play_period > 0ms) {
                    play_due_ += step;
                    if (play_due_ >= options_.play_period) {
                        play_due_ = 0ns;
                        play = true;
                    }
                }
            }
        }
        // A bump while a call is outstanding is remembered and played once that call returns: the
        // bump call is the one a client waits for; periodic ones may be skipped.
        if (streaming && bumps > 0) bump_play_pending_ = true;
        if (!streaming) bump_play_pending_ = false;
        if (bump_play_pending_ && !play_outstanding_) {
            bump_play_pending_ = false;
            play = true;
        }
        if (play && (play_outstanding_ || !streaming)) play = false;
        if (play) {
            play_outstanding_ = true;
            ++play_stats_.calls;
            play_target = streamers_.back();
            play_distance = round_i32(sim_.state().distance_mm);
            play_angle = round_i32(sim_.state().angle_deg);
        }
        if (packet_due) {
            sequence_ = sequence_ == 0xFFFF ? 1 : static_cast<std::uint16_t>(sequence_ + 1);
            packet = make_packet_locked(sequence_);
        }
    }
    for (std::uint32_t i = 0; i < bumps; ++i) (void)object_->fire_event("Bump", {});
    if (packet) (void)packets_->set_out_value(std::move(*packet));
    if (play) call_play(play_target, play_distance, play_angle);
}

void CreateDevice::call_play(const SessionRef& target, std::int32_t distance, std::int32_t angle) {
    std::weak_ptr<CreateDevice> weak = weak_from_this();
    play_callback_->call(target, {Value::scalar<std::int32_t>(distance), Value::scalar<std::int32_t>(angle)},
                [weak, target](Result<Value> r) {
                    auto self = weak.lock();
                    if (!self) return;
                    std::lock_guard lock(self->mutex_);
                    self->play_outstanding_ = false;
                    const NumericArray* song = r ? r->get_if<NumericArray>() : nullptr;
                    if (!song || song->type() != DataTypes::uint8_t) {
                        ++self->play_stats_.errors;
                        if (!r && r.error().type == MessageErrorType::ConnectionError) std::erase(self->streamers_, target);
                        return;
                    }
                    ++self->play_stats_.replies;
                    const auto items = song->view<std::uint8_t>();
                    self->play_stats_.last_song.assign(items.begin(), items.end());
                    if (self->play_stats_.last_song.size() > kMaxSongBytes) self->play_stats_.last_song.resize(kMaxSongBytes);
                });
}

void CreateDevice::start(asio::io_context& io) {
    driver_ = PeriodicTask::start(io, options_.step_period, [weak = weak_from_this()](std::chrono::nanoseconds dt) {
        if (auto self = weak.lock()) self->advance(dt);
    });
}

void CreateDevice::stop() {
    if (driver_) driver_->stop();
}

}  // namespace rr::server::demo
