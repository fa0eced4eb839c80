#include "server/record/replay_device.hpp"

#include <cmath>

#include "core/mcap/mcap_reader.hpp"
#include "core/value/pack_value.hpp"
#include "core/names/object_path_walk.hpp"
#include "base/names/service_path.hpp"
#include "server/mcap/mcap_file.hpp"
#include "server/record/recording_format.hpp"
#include "server/service/pipe_member.hpp"
#include "server/service/wire_member.hpp"

namespace rr::server::record {

nlohmann::json replay_status_json(const ReplayStatus& s) {
    nlohmann::json j{{"name", s.name},         {"file", s.file},         {"recorded_device", s.recorded_device},
                     {"object_type", s.object_type}, {"state", s.state}, {"position_s", s.position_s},
                     {"duration_s", s.duration_s}, {"start_ns", s.start_ns}, {"speed", s.speed},
                     {"loop", s.loop},         {"played", s.played},     {"members", s.members}};
    if (!s.error.empty()) j["error"] = s.error;
    return j;
}

namespace {

RRError refused(const std::string& name, const std::string& file) {
    return make_error(MessageErrorType::InvalidOperation,
                   "device \"" + name + "\" is a recording (" + file + "): functions are not replayed");
}

}  // namespace

struct ReplayDevice::Playback {
    std::unique_ptr<mcap::FileSource> source;
    std::optional<mcap::McapReader> reader;
    std::set<std::uint16_t> all_ids, state_ids;  // every replayed channel; wires and properties
};

Result<std::shared_ptr<ReplayDevice>> ReplayDevice::open(ReplayOptions options) {
    const std::string file = options.file;
    auto err = [&](MessageErrorType t, const std::string& m) { return fail(t, "replay " + file + ": " + m); };
    if (!(options.speed > 0) || options.speed > 1000) return err(MessageErrorType::InvalidArgument, "speed must be above 0 and at most 1000");
    std::shared_ptr<ReplayDevice> d(new ReplayDevice());
    d->options_ = options;
    d->playback_ = std::make_unique<Playback>();
    auto src = mcap::FileSource::open(file);
    if (!src) return fail(src.error().type, "replay: " + src.error().message);
    d->playback_->source = std::move(*src);
    mcap::ReaderLimits limits;
    limits.max_memory_bytes = options.memory_bytes;
    auto reader = mcap::McapReader::open(*d->playback_->source, limits);
    if (!reader) return err(reader.error().type, reader.error().message);
    d->playback_->reader.emplace(std::move(*reader));
    const auto& summary = d->playback_->reader->summary();

    // The channels replay plays: those of the format that replays (robotraconteur_format.cpp).
    const auto& formats = builtin_recording_formats();
    auto played = [&](const mcap::Channel& ch) { return replay_format(formats, ch.message_encoding); };
    auto meta_of = [](const mcap::Channel& ch, const char* k) { return metadata_value(ch.metadata, k); };
    // The root object's type: a root channel's `object_type` (its schema is the root's definition),
    // else `root_type` of a channel below the root (a file of objects below the root only).
    std::string root_type;
    std::uint16_t root_schema = 0;
    for (const auto& [id, ch] : summary.channels) {
        if (!played(ch)) continue;
        if (meta_of(ch, channel_key::path).empty()) {
            root_type = meta_of(ch, channel_key::object_type);
            root_schema = ch.schema_id;
            d->recorded_device_ = meta_of(ch, channel_key::device);
            break;
        }
        if (root_type.empty()) {
            root_type = meta_of(ch, channel_key::root_type);
            d->recorded_device_ = meta_of(ch, channel_key::device);
        }
    }
    if (root_type.empty())
        return err(MessageErrorType::InvalidArgument, "no \"robotraconteur\" channel naming its object type (record with encoding robotraconteur to replay)");
    const std::string root_service = root_type.substr(0, root_type.rfind('.'));
    // The definitions: every robotraconteur_servicedef schema, the root's first.
    std::vector<std::string> texts;
    for (const auto& [id, s] : summary.schemas) {
        if (s.encoding != kServiceDefinitionSchemaEncoding) continue;
        std::string text(reinterpret_cast<const char*>(s.data.data()), s.data.size());
        if (id == root_schema || (!root_schema && s.name == root_service)) texts.insert(texts.begin(), std::move(text));
        else texts.push_back(std::move(text));
    }
    if (texts.empty()) return err(MessageErrorType::InvalidArgument, "no service definition (schema encoding robotraconteur_servicedef)");
    auto types = ServiceTypes::create(texts);
    if (!types) return err(MessageErrorType::InvalidArgument, "recorded service definitions: " + types.error().message);
    d->types_ = *types;

    d->object_type_ = root_type;
    std::map<std::uint16_t, std::string> channel_types;  // object type of each replayed channel
    for (const auto& [id, channel] : summary.channels) {
        const auto& ch = channel;
        const auto* format = played(ch);
        if (!format) continue;
        auto meta = [&](const char* k) { return meta_of(ch, k); };
        const std::string path = meta(channel_key::path), type = meta(channel_key::object_type);
        if (path.empty() && type != d->object_type_) continue;  // not this device's root
        if (auto r = format->check_replay_channel(ch); !r) return err(r.error().type, r.error().message);
        const auto* obj = d->types_->find_object(type);
        if (!obj) return err(MessageErrorType::InvalidArgument, "the recorded definitions have no object type \"" + type + "\" (channel " + ch.topic + ")");
        const std::string member = meta(channel_key::member);
        const auto* m = obj->find_member(member);
        if (!m) return err(MessageErrorType::InvalidArgument, type + " has no member \"" + member + "\" (channel " + ch.topic + ")");
        Channel c;
        c.format = format;
        c.member = m;
        c.path = path;
        c.context = type.substr(0, type.rfind('.'));
        c.property_key = path + '\n' + m->name;
        const std::string kind = meta(channel_key::kind);
        const auto recorded = member_kind_from_name(kind);
        const bool matches = recorded && ((*recorded == RecordedKind::wire && m->kind == robdef::MemberKind::wire) ||
                                          (*recorded == RecordedKind::pipe && m->kind == robdef::MemberKind::pipe) ||
                                          (*recorded == RecordedKind::event && m->kind == robdef::MemberKind::event) ||
                                          (*recorded == RecordedKind::property && m->kind == robdef::MemberKind::property));
        if (!matches) return err(MessageErrorType::InvalidArgument, "channel " + ch.topic + ": kind \"" + kind + "\" does not match member " + m->name);
        c.kind = *recorded;
        d->channels_[id] = c;
        channel_types[id] = type;
        d->playback_->all_ids.insert(id);
        if (c.kind == RecordedKind::wire || c.kind == RecordedKind::property) d->playback_->state_ids.insert(id);
    }
    if (d->channels_.empty()) return err(MessageErrorType::InvalidArgument, "no replayable channel");
    d->context_service_ = d->object_type_.substr(0, d->object_type_.rfind('.'));
    d->name_ = options.name.empty() ? d->recorded_device_ : options.name;
    if (d->name_.empty()) return err(MessageErrorType::InvalidArgument, "no device name (the channels do not name the device; give one)");

    // The time range: the statistics, else the chunk indexes.
    const auto& st = summary.statistics;
    d->start_ns_ = st.message_start_time;
    d->end_ns_ = st.message_end_time;
    if (!d->end_ns_) {
        for (const auto& ci : summary.chunk_indexes) {
            if (!d->start_ns_ || (ci.message_start_time && ci.message_start_time < d->start_ns_)) d->start_ns_ = ci.message_start_time;
            d->end_ns_ = std::max(d->end_ns_, ci.message_end_time);
        }
    }

    auto root = ServiceObject::create(d->types_, d->object_type_);
    if (!root) return err(MessageErrorType::InvalidArgument, root.error().message);
    d->root_ = *root;
    d->objects_[""] = d->root_;
    d->serve_members(*d->root_, "");
    for (auto& [id, c] : d->channels_) {
        auto object = d->object_at(c.path, channel_types[id]);
        if (!object) return err(MessageErrorType::InvalidArgument, object.error().message);
        c.object = *object;
    }
    auto service = ObjectService::create(d->name_, d->root_);
    if (!service) return err(MessageErrorType::InvalidArgument, service.error().message);
    d->service_ = *service;
    d->speed_ = options.speed;
    d->loop_ = options.loop;
    d->playing_ = !options.paused;
    return d;
}

void ReplayDevice::serve_members(ServiceObject& object, const std::string& path) {
    std::weak_ptr<ReplayDevice> weak = weak_from_this();
    const std::string name = name_, file = options_.file;
    for (const auto& m : object.definition().members) {
        if (m.kind == robdef::MemberKind::function) {
            if (m.is_generator())
                (void)object.set_generator_function(m.name, [name, file](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
                    return fail(refused(name, file));
                });
            else
                (void)object.set_function(m.name, [name, file](const SessionRef&, std::vector<Value>) -> Result<Value> { return fail(refused(name, file)); });
        } else if (m.kind == robdef::MemberKind::property) {
            const std::string member = m.name, key = path + '\n' + m.name;
            (void)object.set_property_handlers(
                m.name,
                [weak, member, key, file](const SessionRef&) -> Result<Value> {
                    auto self = weak.lock();
                    if (!self) return fail(MessageErrorType::ServiceError, "replay ended");
                    std::lock_guard<std::mutex> lock(self->mutex_);
                    auto it = self->properties_.find(key);
                    if (it == self->properties_.end())
                        return fail(MessageErrorType::ValueNotSet, "property \"" + member + "\" has no recorded value at this point of " + file);
                    return it->second;
                },
                [name, file](const SessionRef&, Value) -> Result<void> {
                    return fail(MessageErrorType::ReadOnlyMember, "device \"" + name + "\" is a recording (" + file + "): properties are read-only");
                });
        }
    }
}

Result<ServiceObject*> ReplayDevice::object_at(const std::string& path, const std::string& type) {
    if (auto it = objects_.find(path); it != objects_.end()) return it->second.get();
    // Recorded paths are normalized (recording.cpp): indexes in service-path encoding. The whole path
    // must follow the objrefs' declared types (core/names/object_path_walk.hpp), as when it was recorded.
    auto parsed = parse_object_path(path, ObjectPathIndexes::encoded);
    if (!parsed) return fail(parsed.error());
    ObjectPath last;
    last.segments.push_back(std::move(parsed->segments.back()));
    parsed->segments.pop_back();
    const std::string member = last.segments[0].name, parent_path = parsed->text();
    std::string parent_type = object_type_;
    if (!parsed->segments.empty()) {
        auto at = walk_object_path(types_->set(), object_type_, *parsed, path);
        if (!at) return fail(at.error());
        parent_type = at->object_type;
    }
    if (auto at = walk_object_path(types_->set(), parent_type, last, path); !at) return fail(at.error());
    // The parent: already served, else served now.
    ServiceObject* parent = nullptr;
    if (auto it = objects_.find(parent_path); it != objects_.end()) {
        parent = it->second.get();
    } else {
        auto p = object_at(parent_path, parent_type);
        if (!p) return p.take_error();
        parent = *p;
    }
    auto object = ServiceObject::create(types_, type);
    if (!object) return fail(MessageErrorType::InvalidArgument, "object path \"" + path + "\": " + object.error().message);
    objects_[path] = *object;
    serve_members(**object, path);
    // The parent's objref answers the recorded objects (objects_ is complete before serving starts).
    std::weak_ptr<ReplayDevice> weak = weak_from_this();
    const std::string file = options_.file;
    (void)parent->set_objref(member, [weak, parent_path, member, file](const SessionRef&, const ObjRefIndex& index)
                                         -> Result<std::shared_ptr<ServiceObject>> {
        auto self = weak.lock();
        if (!self) return fail(MessageErrorType::ServiceError, "replay ended");
        std::string seg = member;
        if (const auto* i = std::get_if<std::int32_t>(&index)) seg += "[" + encode_service_path_index(*i) + "]";
        else if (const auto* k = std::get_if<std::string>(&index)) seg += "[" + encode_service_path_index(std::string_view(*k)) + "]";
        const std::string p = parent_path.empty() ? seg : parent_path + "." + seg;
        auto it = self->objects_.find(p);
        if (it == self->objects_.end())
            return fail(MessageErrorType::ObjectNotFound, "object \"" + p + "\" was not recorded (not in the recording " + file + ")");
        return it->second;
    });
    return object->get();
}

ReplayDevice::~ReplayDevice() { stop(); }

void ReplayDevice::start() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (thread_.joinable()) return;
    seek_to_ = start_ns_;
    thread_ = std::thread([this] { run(); });
}

void ReplayDevice::stop() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stop_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable() && thread_.get_id() != std::this_thread::get_id()) thread_.join();
    for (auto& [path, object] : objects_) object->clear_handlers();
    if (service_) service_->shutdown();
}

void ReplayDevice::play() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (ended_) seek_to_ = start_ns_;  // play at the end starts again
        playing_ = true;
        anchor_file_ns_ = position_ns_;
        anchor_steady_ = std::chrono::steady_clock::now();
    }
    wake_.notify_all();
}

void ReplayDevice::pause() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        playing_ = false;
    }
    wake_.notify_all();
}

Result<void> ReplayDevice::seek(double seconds) {
    if (!std::isfinite(seconds) || seconds < 0) return fail(MessageErrorType::InvalidArgument, "seek: expected seconds >= 0");
    const double span = static_cast<double>(end_ns_ - start_ns_);
    const double ns = std::min(seconds * 1e9, span);
    {
        std::lock_guard<std::mutex> lock(mutex_);
        seek_to_ = start_ns_ + static_cast<std::uint64_t>(ns);
    }
    wake_.notify_all();
    return {};
}

Result<void> ReplayDevice::set_speed(double speed) {
    if (!(speed > 0) || speed > 1000) return fail(MessageErrorType::InvalidArgument, "speed: expected a number above 0 and at most 1000");
    {
        std::lock_guard<std::mutex> lock(mutex_);
        // Re-anchored where the replay is now, so the change applies from this moment.
        const auto now = std::chrono::steady_clock::now();
        if (playing_ && !ended_) {
            const double elapsed = std::chrono::duration<double, std::nano>(now - anchor_steady_).count() * speed_;
            anchor_file_ns_ = std::max(position_ns_, anchor_file_ns_ + static_cast<std::uint64_t>(elapsed));
        }
        anchor_steady_ = now;
        speed_ = speed;
    }
    wake_.notify_all();
    return {};
}

void ReplayDevice::set_loop(bool loop) {
    std::lock_guard<std::mutex> lock(mutex_);
    loop_ = loop;
}

ReplayStatus ReplayDevice::status() const {
    ReplayStatus s;
    s.name = name_;
    s.file = options_.file;
    s.recorded_device = recorded_device_;
    s.object_type = object_type_;
    s.start_ns = start_ns_;
    s.duration_s = static_cast<double>(end_ns_ - start_ns_) / 1e9;
    s.played = played_.load();
    for (const auto& [id, c] : channels_) s.members.push_back(c.path.empty() ? c.member->name : c.path + "." + c.member->name);
    std::lock_guard<std::mutex> lock(mutex_);
    s.speed = speed_;
    s.loop = loop_;
    s.error = error_;
    s.state = !error_.empty() ? "failed" : ended_ ? "ended" : playing_ ? "playing" : "paused";
    std::uint64_t pos = position_ns_;
    if (playing_ && !ended_ && error_.empty()) {
        const double elapsed = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - anchor_steady_).count() * speed_;
        pos = std::min(end_ns_, std::max(pos, anchor_file_ns_ + static_cast<std::uint64_t>(elapsed)));
    }
    s.position_s = static_cast<double>(pos - std::min(pos, start_ns_)) / 1e9;
    return s;
}

void ReplayDevice::apply(std::uint16_t channel, std::span<const std::byte> data, bool live) {
    auto it = channels_.find(channel);
    if (it == channels_.end()) return;
    const auto& c = it->second;
    auto entry = c.format->read_entry(data);
    if (!entry) return;  // a malformed recorded entry is skipped
    const auto& set = types_->set();
    auto unpack = [&](const MessageElement* el, const robdef::TypeDefinition& type) -> std::optional<Value> {
        if (!el) return std::nullopt;
        auto v = unpack_value(*el, type, set, c.context);
        if (!v) return std::nullopt;
        return std::move(*v);
    };
    switch (c.kind) {
        case RecordedKind::wire: {
            auto v = unpack(entry->find("packet"), c.member->type);
            if (!v) return;
            if (auto w = c.object->wire(c.member->name)) (void)(*w)->set_out_value(std::move(*v));
            break;
        }
        case RecordedKind::pipe: {
            if (!live || entry->elements.empty()) return;
            auto v = unpack(&entry->elements[0], c.member->type);
            if (!v) return;
            if (auto p = c.object->pipe(c.member->name)) (*p)->broadcast(*v);
            break;
        }
        case RecordedKind::event: {
            if (!live) return;
            std::vector<Value> args;
            for (const auto& p : c.member->parameters) {
                auto v = unpack(entry->find(p.name), p);
                if (!v) return;
                args.push_back(std::move(*v));
            }
            (void)c.object->fire_event(c.member->name, std::move(args));
            break;
        }
        case RecordedKind::property: {
            auto v = unpack(entry->find("value"), c.member->type);
            if (!v) return;
            std::lock_guard<std::mutex> lock(mutex_);
            properties_[c.property_key] = std::move(*v);
            break;
        }
    }
}

void ReplayDevice::restore_state(std::uint64_t t_ns) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        properties_.clear();
    }
    mcap::MessageQuery q;
    q.start_time = 0;
    q.end_time = t_ns + 1;
    q.channels = playback_->state_ids;
    auto it = playback_->reader->messages(q);
    std::map<std::uint16_t, mcap::Message> last_wire;
    for (;;) {
        auto m = it.next();
        if (!m || !*m) break;
        auto& msg = **m;
        if (channels_[msg.channel_id].kind == RecordedKind::wire) last_wire[msg.channel_id] = std::move(msg);
        else apply(msg.channel_id, msg.data, false);
    }
    // Each wire's value at that point, once (the clients see where the seek landed).
    for (const auto& [id, msg] : last_wire) apply(id, msg.data, true);
}

void ReplayDevice::run() {
    using clock = std::chrono::steady_clock;
    std::optional<mcap::MessageIterator> iter;
    std::optional<mcap::Message> next;
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
        if (seek_to_) {
            const std::uint64_t t = *seek_to_;
            seek_to_.reset();
            lock.unlock();
            iter.reset();  // its decoded chunks count in the reader's memory: gone before restore_state reads
            next.reset();
            restore_state(t);
            mcap::MessageQuery q;
            q.start_time = t;
            q.channels = playback_->all_ids;
            iter.emplace(playback_->reader->messages(q));
            next.reset();
            lock.lock();
            position_ns_ = anchor_file_ns_ = t;
            anchor_steady_ = clock::now();
            ended_ = false;
            continue;
        }
        if (!playing_ || ended_ || !error_.empty()) {
            wake_.wait(lock, [&] { return stop_ || seek_to_ || (playing_ && !ended_ && error_.empty()); });
            continue;
        }
        if (!next) {
            lock.unlock();
            auto m = iter->next();
            lock.lock();
            if (!m) {
                error_ = "replay " + options_.file + ": " + m.error().message;
                if (options_.on_error) {
                    const auto error = error_;
                    lock.unlock();
                    options_.on_error(name_, error);
                    lock.lock();
                }
                continue;
            }
            if (!*m) {
                if (loop_) seek_to_ = start_ns_;
                else ended_ = true, position_ns_ = end_ns_;
                continue;
            }
            next = std::move(**m);
        }
        const std::uint64_t at = next->log_time;
        const double offset = at > anchor_file_ns_ ? static_cast<double>(at - anchor_file_ns_) / speed_ : 0.0;
        const auto due = anchor_steady_ + std::chrono::nanoseconds(static_cast<std::int64_t>(offset));
        const bool interrupted = wake_.wait_until(lock, due, [&] { return stop_ || seek_to_ || !playing_; });
        if (interrupted) continue;
        if (clock::now() < due) continue;  // woken early (a speed change re-anchored): wait again
        position_ns_ = std::max(position_ns_, at);
        lock.unlock();
        apply(next->channel_id, next->data, true);
        played_.fetch_add(1, std::memory_order_relaxed);
        next.reset();
        lock.lock();
    }
}

}  // namespace rr::server::record
