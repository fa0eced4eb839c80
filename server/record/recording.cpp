#include "server/record/recording.hpp"

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <map>
#include <optional>
#include <pthread.h>
#include <system_error>

#include "core/mcap/mcap_writer.hpp"
#include "core/value/timespec.hpp"
#include "robdef/parser.hpp"
#include "server/gateway/mirror_service.hpp"
#include "server/gateway/session_endpoints.hpp"
#include "server/mcap/mcap_file.hpp"

namespace rr::server::record {

namespace fs = std::filesystem;
using gateway::SharedEntry;
using gateway::SharedEntryPtr;

std::string_view recording_state_name(RecordingState s) noexcept {
    switch (s) {
        case RecordingState::recording: return "recording";
        case RecordingState::stopping: return "stopping";
        case RecordingState::stopped: return "stopped";
        case RecordingState::failed: return "failed";
    }
    return "?";
}

nlohmann::json status_json(const RecordingStatus& s) {
    nlohmann::json j{{"id", s.id},           {"device", s.spec.device},   {"state", recording_state_name(s.state)},
                     {"files", s.files},     {"bytes", s.bytes},          {"messages", s.messages},
                     {"drops", s.drops},     {"queued_bytes", s.queued_bytes}, {"duration_s", s.duration_s},
                     {"connecting", s.connecting},
                     {"members", s.members}, {"spec", spec_json(s.spec)}};
    if (!s.error.empty()) j["error"] = s.error;
    return j;
}

namespace {

std::uint64_t now_ns() {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

// The recorder's threads by name (pthread names are at most 15 characters): per-thread CPU in
// /proc/<pid>/task/*/stat tells the recorder's cost from the live path's (bench/run.py, record section).
void name_recorder_thread(const char* name) { pthread_setname_np(pthread_self(), name); }

// How long the writer lets entries gather before it takes them (earlier when the queue is half full).
constexpr std::chrono::milliseconds recorder_writer_period{50};

std::string utc_stamp() {
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y%m%dT%H%M%SZ", &tm);
    return buf;
}

// The service name each definition text declares (`service a.b.c`), read by the robdef parser (the
// texts parsed already as the device's types): the schemas' names.
std::vector<std::string> declared_service_names(const std::vector<std::string>& texts) {
    std::vector<std::string> names;
    for (const auto& text : texts) {
        auto parsed = robdef::parse_service_definition(text, "device definition");
        names.push_back(parsed ? parsed->definition.name : "unknown");
    }
    return names;
}

std::span<const std::byte> as_bytes(std::string_view s) { return {reinterpret_cast<const std::byte*>(s.data()), s.size()}; }

}  // namespace

// The open MCAP file (its channels are the formats' encoders').
struct Recording::File {
    std::string path;
    std::unique_ptr<mcap::FileSink> sink;
    std::unique_ptr<mcap::McapWriter> writer;
    std::chrono::steady_clock::time_point opened = std::chrono::steady_clock::now();
    std::size_t summary_base = 0;  // the writer's summary memory once schemas and channels were added
};

// The default file name prefix: the device's name with the characters a prefix may not have as '_'.
static std::string prefix_of_device(const std::string& device) {
    std::string p = device.substr(0, 64);
    for (auto& c : p)
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.')) c = '_';
    if (p.empty() || p.front() == '.') p.insert(p.begin(), '_');
    return p.substr(0, 64);
}

Result<std::shared_ptr<Recording>> Recording::create(std::uint64_t id, RecordingSpec spec, std::shared_ptr<gateway::DeviceMirror> device,
                                                     std::shared_ptr<gateway::JsonApi> api, std::shared_ptr<RecordingsRoot> root,
                                                     RecordingListeners listeners, const RecordingFormats& formats) {
    if (!device || !api) return fail(MessageErrorType::InvalidArgument, "record: no such device \"" + spec.device + "\"");
    if (!root) return fail(MessageErrorType::InvalidState, "record: no recordings root");
    if (auto r = check_subfolder(spec.directory); !r) return r.take_error();
    if (auto r = check_prefix(spec.prefix); !r) return r.take_error();
    for (const auto& e : spec.encodings)
        if (std::none_of(formats.begin(), formats.end(), [&](const auto& f) { return f->is_encoding() && f->name() == e; }))
            return fail(MessageErrorType::InvalidArgument, "record: encoding: no format \"" + e + "\"");
    if (std::none_of(formats.begin(), formats.end(), [&](const auto& f) { return f->enabled(spec); }))
        return fail(MessageErrorType::InvalidArgument, "record: encoding: no format to write");
    if (!device->upstream())
        return fail(MessageErrorType::InvalidState, "record: device \"" + spec.device + "\" is not connected (its definitions are needed)");
    auto members = recorded_members(device, *api, spec.members, spec.property_period);
    if (!members) return members.take_error();

    if (spec.prefix.empty()) spec.prefix = prefix_of_device(spec.device);

    auto definition_names = declared_service_names(members->front().target->types->texts());
    std::shared_ptr<Recording> r(new Recording(id, std::move(spec), std::move(device), std::move(api), std::move(root), std::move(*members),
                                               std::move(definition_names), formats));
    r->listeners_ = std::move(listeners);
    // The thread keeps the recording alive until it has ended; the disk work is all done there.
    r->writer_ = std::thread([self = r] { self->writer_loop(); });
    return r;
}

Result<std::shared_ptr<Recording>> Recording::start(std::uint64_t id, RecordingSpec spec, std::shared_ptr<gateway::DeviceMirror> device,
                                                    std::shared_ptr<gateway::JsonApi> api, std::shared_ptr<RecordingsRoot> root,
                                                    const RecordingFormats& formats) {
    struct Outcome {
        std::mutex mutex;
        std::condition_variable cv;
        std::optional<Result<void>> result;
    };
    auto outcome = std::make_shared<Outcome>();
    RecordingListeners l;
    l.started = [outcome](Recording&, const Result<void>& started) {
        std::lock_guard<std::mutex> lock(outcome->mutex);
        outcome->result = started;
        outcome->cv.notify_all();
    };
    auto r = create(id, std::move(spec), std::move(device), std::move(api), std::move(root), std::move(l), formats);
    if (!r) return r;
    std::unique_lock<std::mutex> lock(outcome->mutex);
    outcome->cv.wait(lock, [&] { return outcome->result.has_value(); });
    if (!*outcome->result) {
        lock.unlock();
        (*r)->wait();
        return fail(outcome->result->error());
    }
    return r;
}

Recording::Recording(std::uint64_t id, RecordingSpec spec, std::shared_ptr<gateway::DeviceMirror> device,
                     std::shared_ptr<gateway::JsonApi> api, std::shared_ptr<RecordingsRoot> root, std::vector<RecordedMember> members,
                     std::vector<std::string> definition_names, const RecordingFormats& formats)
    : id_(id),
      spec_(std::move(spec)),
      device_(std::move(device)),
      api_(std::move(api)),
      root_(std::move(root)),
      members_(std::move(members)),
      definition_names_(std::move(definition_names)),
      queue_(spec_.queue_bytes) {
    for (const auto& f : formats)
        if (f->enabled(spec_)) encoders_.push_back(f->encoder(format_context_));
    sequence_.assign(encoders_.size() * members_.size(), 0);
}

Recording::~Recording() {
    stop();
    wait();
}

void Recording::wait() {
    // The last reference may go on the writer thread itself (it holds one): it cannot join itself.
    if (!writer_.joinable()) return;
    if (writer_.get_id() == std::this_thread::get_id()) writer_.detach();
    else writer_.join();
}

// --- the live path -------------------------------------------------------------------------------

void Recording::offer(std::uint16_t member, SharedEntryPtr entry) { (void)queue_.offer(member, now_ns(), std::move(entry)); }

void Recording::offer_wire(std::uint16_t member, SharedEntryPtr entry) {
    (void)queue_.offer_newest(member, now_ns(), std::move(entry));
}

void Recording::subscribe_members() {
    std::weak_ptr<Recording> weak = weak_from_this();
    {
        // Before the first subscribe: its answer may come at once, on this thread.
        std::lock_guard<std::mutex> lock(mutex_);
        connecting_ = static_cast<std::size_t>(std::count_if(members_.begin(), members_.end(), [](const RecordedMember& m) {
            return m.kind != RecordedMember::Kind::property;
        }));
    }
    for (std::size_t i = 0; i < members_.size(); ++i) {
        const auto& m = members_[i];
        const auto index = static_cast<std::uint16_t>(i);
        const auto& t = *m.target;
        if (m.kind == RecordedMember::Kind::wire || m.kind == RecordedMember::Kind::event) {
            auto sid = device_->subscribe(
                t.path, t.member->name, m.kind == RecordedMember::Kind::wire,
                [weak, index, is_wire = m.kind == RecordedMember::Kind::wire](const SharedEntryPtr& e) {
                    // WireClosed has no value: only values are recorded.
                    if (e->entry().entry_type == MessageEntryType::WireClosed) return;
                    auto self = weak.lock();
                    if (!self) return;
                    if (is_wire)
                        self->offer_wire(index, e);
                    else
                        self->offer(index, e);
                },
                [weak](Result<void>) {  // a wire not connected now is connected when the device is back
                    if (auto self = weak.lock()) self->member_answered();
                });
            std::unique_lock<std::mutex> lock(mutex_);
            if (stopping_) {  // stopped while subscribing: unsubscribe_members has run already
                lock.unlock();
                device_->unsubscribe(sid);
                continue;
            }
            subscriptions_.push_back(sid);
        } else if (m.kind == RecordedMember::Kind::pipe) {
            gateway::GatewayPipeHandlers h;
            const std::string path = t.path, member = t.member->name;
            h.on_packet = [weak, index, path, member](const MessageElement& packet, std::uint32_t) {
                auto self = weak.lock();
                if (!self) return;
                MessageEntry e;
                e.entry_type = MessageEntryType::PipePacket;
                e.service_path = path;
                e.member_name = member;
                e.elements.push_back(packet);  // its bytes are shared (SharedBytes), not copied
                self->offer(index, std::make_shared<SharedEntry>(std::move(e)));
            };
            h.on_closed = [](const RRError&) {};
            device_->mirror_service()->shared_endpoints()->open_pipe(
                t.path, t.member->name, robdef::pipe_is_unreliable(*t.object, *t.member), std::move(h),
                [weak](Result<std::uint64_t> id) {
                    auto self = weak.lock();
                    if (!self) return;
                    self->member_answered();
                    if (!id) return;
                    std::unique_lock<std::mutex> lock(self->mutex_);
                    if (self->stopping_) {
                        lock.unlock();
                        self->device_->mirror_service()->shared_endpoints()->close_pipe(*id);
                        return;
                    }
                    self->pipes_.push_back(*id);
                });
        }
    }
}

void Recording::member_answered() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (connecting_) --connecting_;
}

void Recording::unsubscribe_members() {
    std::vector<std::uint64_t> subs, pipes;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        subs.swap(subscriptions_);
        pipes.swap(pipes_);
    }
    for (auto id : subs) device_->unsubscribe(id);
    for (auto id : pipes) device_->mirror_service()->shared_endpoints()->close_pipe(id);
}

void Recording::poll_loop() {
    name_recorder_thread("rr-record-poll");
    const auto period = spec_.property_period.count() > 0 ? spec_.property_period : std::chrono::milliseconds(1000);
    auto outstanding = std::make_shared<std::atomic<int>>(0);
    std::weak_ptr<Recording> weak = weak_from_this();
    auto next = std::chrono::steady_clock::now();
    for (;;) {
        {
            std::unique_lock<std::mutex> lock(mutex_);
            if (poll_wake_.wait_until(lock, next, [&] { return stopping_; })) return;
        }
        next += period;
        if (outstanding->load() > 0) continue;  // the device is slower than the period: skip a round
        for (std::size_t i = 0; i < members_.size(); ++i) {
            if (members_[i].kind != RecordedMember::Kind::property) continue;
            const auto& t = *members_[i].target;
            MessageEntry e;
            e.entry_type = MessageEntryType::PropertyGetReq;
            e.service_path = t.path;
            e.member_name = t.member->name;
            outstanding->fetch_add(1);
            device_->request(std::move(e), [weak, outstanding, index = static_cast<std::uint16_t>(i)](Result<MessageEntry> r) {
                outstanding->fetch_sub(1);
                auto self = weak.lock();
                if (!self || !r || r->error != MessageErrorType::None) return;
                self->offer(index, std::make_shared<SharedEntry>(std::move(*r)));
            });
        }
    }
}

// --- the writer thread ------------------------------------------------------------------------------

Result<void> Recording::begin() {
    // At least room for the first chunk when the recording has no budget of its own.
    const std::uint64_t at_least = std::max<std::uint64_t>(spec_.chunk_bytes, 1u << 20);
    auto admitted = root_->admit(spec_.max_total_bytes, at_least);
    if (!admitted) return admitted.take_error();
    admission_ = std::move(*admitted);
    auto folder = root_->open_folder(spec_.directory);
    if (!folder) return folder.take_error();
    folder_ = std::move(*folder);
    if (auto r = open_file(); !r) return r;
    subscribe_members();
    if (std::any_of(members_.begin(), members_.end(), [](const RecordedMember& m) { return m.kind == RecordedMember::Kind::property; }))
        poller_ = std::thread([this] { poll_loop(); });
    return {};
}

Result<void> Recording::open_file() {
    enforce_budget();
    auto f = std::make_unique<File>();
    char number[24];
    std::snprintf(number, sizeof number, "-%03llu", static_cast<unsigned long long>(++file_counter_));
    const std::string stem = spec_.prefix + "-" + utc_stamp() + number;
    // A name already taken (a recording of the same prefix started in the same second, a file left
    // there) is never opened: the next one is tried.
    std::string name;
    for (int k = 1;; ++k) {
        name = k == 1 ? stem + ".mcap" : stem + "-" + std::to_string(k) + ".mcap";
        bool exists = false;
        auto sink = folder_->create_file(name, &exists);
        if (sink) {
            f->sink = std::move(*sink);
            break;
        }
        if (!exists || k >= 1000) return sink.take_error();
    }
    f->path = folder_->path_of(name);
    mcap::WriterOptions wo;
    wo.library = "rr-gateway recorder";
    wo.chunk_size = spec_.chunk_bytes;
    wo.compression = spec_.compress ? mcap::Compression::Zstd : mcap::Compression::None;
    f->writer = std::make_unique<mcap::McapWriter>(*f->sink, wo);
    auto check = [&](Result<void> r) -> Result<void> {
        if (!r) return fail(r.error().type, "record: " + f->path + ": " + r.error().message);
        return {};
    };
    if (auto r = check(f->writer->open()); !r) return r;

    // The device's service definitions (root first), for replay and RR tools: a format's channels may
    // refer to them (FormatFile::definition_schema). Then each format's schemas and channels.
    const auto& texts = members_.front().target->types->texts();
    std::uint16_t root_schema = 0;
    std::map<std::string, std::uint16_t> definition_schemas;  // service name -> schema id
    for (std::size_t i = 0; i < texts.size(); ++i) {
        auto id = f->writer->add_schema(definition_names_[i], kServiceDefinitionSchemaEncoding, as_bytes(texts[i]));
        if (!id) return check(id.take_error());
        if (i == 0) root_schema = *id;
        definition_schemas.emplace(definition_names_[i], *id);
    }
    FormatFile file(*f->writer, f->path, definition_schemas, root_schema);
    for (auto& encoder : encoders_)
        if (auto r = encoder->open_file(file); !r) return r;
    f->summary_base = f->writer->summary_memory_bytes();
    // Schemas and channels on disk at once: a file killed before its first full chunk still names them.
    if (auto r = check(f->writer->flush()); !r) return r;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        files_.push_back(FileEntry{name, f->path, f->writer->bytes_written()});
    }
    file_ = std::move(f);
    note_file_size();
    return {};
}

Result<void> Recording::close_file() {
    if (!file_) return {};
    auto f = std::move(file_);
    auto r = f->writer->close();
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!files_.empty()) files_.back().size = f->writer->bytes_written();
    }
    auto c = f->sink->close();
    if (!r) return fail(r.error().type, "record: " + f->path + ": " + r.error().message);
    if (!c) return fail(c.error().type, "record: " + f->path + ": " + c.error().message);
    return {};
}

// The disk budget: the oldest closed files go while the files and a full new one would exceed it. Only
// files this recording made are removed, by name, in its own folder (RecordingsFolder::remove_file).
void Recording::enforce_budget() {
    if (!spec_.max_total_bytes) return;
    std::unique_lock<std::mutex> lock(mutex_);
    auto total = [&] {
        std::uint64_t n = 0;
        for (const auto& f : files_) n += f.size;
        return n;
    };
    const std::uint64_t next = spec_.max_file_bytes ? spec_.max_file_bytes : 0;
    std::uint64_t removed = 0;
    while (!files_.empty() && total() + next > spec_.max_total_bytes) {
        (void)folder_->remove_file(files_.front().name);  // already gone (removed by hand): forgotten all the same
        removed += files_.front().size;
        files_.erase(files_.begin());
    }
    lock.unlock();
    if (removed) {
        noted_bytes_ -= std::min(noted_bytes_, removed);
        (void)admission_->note(-static_cast<std::int64_t>(removed));
    }
}

Result<void> Recording::write_item(const Item& item) {
    const auto& m = members_[item.member];
    const MessageEntry& e = item.entry->entry();
    std::uint64_t publish = item.log_ns;
    if (m.kind == RecordedMember::Kind::wire) {
        if (const auto* ts = e.find("packettime"))
            if (auto time = unpack_timespec(*ts); time && time->seconds >= 0)
                publish = static_cast<std::uint64_t>(time->seconds) * 1000000000ull + static_cast<std::uint64_t>(time->nanoseconds);
    }
    const RecordedEntry entry{item.member, *item.entry, item.log_ns};
    for (std::size_t k = 0; k < encoders_.size(); ++k) {
        MessageOut out(*file_->writer, file_->path, item.log_ns, publish, sequence_[k * members_.size() + item.member], messages_);
        if (auto r = encoders_[k]->write(entry, out); !r) return r;
    }
    return {};
}

bool Recording::note_file_size() {
    std::uint64_t total = 0;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (file_ && !files_.empty()) files_.back().size = file_->writer->bytes_written();
        for (const auto& f : files_) total += f.size;
    }
    if (!admission_) return true;
    const auto delta = static_cast<std::int64_t>(total) - static_cast<std::int64_t>(noted_bytes_);
    noted_bytes_ = total;
    return admission_->note(delta);
}

RRError Recording::root_full() const {
    return make_error(MessageErrorType::IOError, "record: the recordings root " + root_->path() + " is full: its files reached " +
                                               std::to_string(root_->max_total_bytes()) +
                                               " bytes with what running recordings set aside (recordings.max_total_bytes)");
}

void Recording::end_failed(const RRError& error, bool started_ok) {
    std::vector<std::function<void(const RecordingStatus&)>> listeners;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        state_ = RecordingState::failed;
        error_ = error.message;
        stopping_ = true;
        ended_ = std::chrono::steady_clock::now();
        listeners.swap(stop_listeners_);
    }
    queue_.close_and_clear();
    poll_wake_.notify_all();
    unsubscribe_members();
    if (poller_.joinable()) poller_.join();
    // What was written stays: its complete chunks are readable; a close that fails again changes nothing.
    if (file_) {
        (void)file_->writer->close();
        (void)file_->sink->close();
        if (admission_) (void)note_file_size();
        file_.reset();
    }
    admission_.reset();  // its share of the root's budget goes back
    folder_.reset();
    auto s = status();
    if (!started_ok && listeners_.started) listeners_.started(*this, Result<void>(fail(error)));
    for (auto& l : listeners) l(s);
    if (started_ok && listeners_.ended) listeners_.ended(s);
}

void Recording::writer_loop() {
    name_recorder_thread("rr-record");
    if (auto r = begin(); !r) return end_failed(r.error(), false);
    if (listeners_.started) listeners_.started(*this, Result<void>());
    using clock = std::chrono::steady_clock;
    auto last_flush = clock::now();
    std::vector<Item> batch;  // swapped with the queue's: both keep their capacity
    bool ending_requested = false;
    for (;;) {
        const bool closed = queue_.take(batch, recorder_writer_period);
        for (const auto& item : batch) {
            const auto now = clock::now();
            const bool too_big = spec_.max_file_bytes && file_->writer->bytes_written() >= spec_.max_file_bytes;
            const bool too_old = spec_.max_file_duration.count() && now - file_->opened >= spec_.max_file_duration;
            // The writer keeps one Chunk Index per chunk for the file's summary: a new file bounds it.
            const bool too_indexed = file_->writer->summary_memory_bytes() - file_->summary_base >= spec_.max_index_bytes;
            if (too_big || too_old || too_indexed) {
                if (auto r = close_file(); !r) return end_failed(r.error(), true);
                if (auto r = open_file(); !r) return end_failed(r.error(), true);
            }
            if (auto r = write_item(item); !r) return end_failed(r.error(), true);
        }
        batch.clear();  // the entries' last references usually go here, off the live path
        if (!note_file_size()) return end_failed(root_full(), true);
        // A chunk at least every second: a killed gateway loses at most about a second.
        if (clock::now() - last_flush >= std::chrono::seconds(1)) {
            last_flush = clock::now();
            if (auto r = file_->writer->flush(); !r)
                return end_failed(make_error(r.error().type, "record: " + file_->path + ": " + r.error().message), true);
            if (!note_file_size()) return end_failed(root_full(), true);
        }
        if (spec_.duration.count() && clock::now() - started_ >= spec_.duration && !closed && !ending_requested) {
            // Ends itself: taps go, then the queue is drained on the next rounds.
            ending_requested = true;
            std::thread([self = shared_from_this()] { self->stop(); }).detach();
        }
        if (closed) {
            // Closed before the swap: `batch` held the last items.
            auto r = close_file();
            if (!r) return end_failed(r.error(), true);
            if (poller_.joinable()) poller_.join();  // stopping_ is set: it has ended or is ending
            (void)note_file_size();
            admission_.reset();
            folder_.reset();
            std::vector<std::function<void(const RecordingStatus&)>> listeners;
            {
                std::lock_guard<std::mutex> l2(mutex_);
                state_ = RecordingState::stopped;
                ended_ = clock::now();
                listeners.swap(stop_listeners_);
            }
            auto s = status();
            for (auto& l : listeners) l(s);
            if (listeners_.ended) listeners_.ended(s);
            return;
        }
    }
}

void Recording::stop(std::function<void(const RecordingStatus&)> done) {
    bool first = false;
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (state_ == RecordingState::recording) {
            state_ = RecordingState::stopping;
            stopping_ = true;
            first = true;
        }
        if (state_ == RecordingState::stopping) {
            if (done) stop_listeners_.push_back(std::move(done));
            done = nullptr;
        }
    }
    if (first) {
        unsubscribe_members();
        queue_.close();  // after the taps are gone: what they queued is written
        poll_wake_.notify_all();
    }
    if (done) done(status());
}

RecordingStatus Recording::status() const {
    RecordingStatus s;
    s.id = id_;
    s.spec = spec_;
    for (const auto& m : members_) {
        const auto object = metadata_value(m.metadata, channel_key::path);
        s.members.push_back(object.empty() ? m.target->member->name : object + "." + m.target->member->name);
    }
    s.drops = queue_.drops();
    s.queued_bytes = queue_.queued_bytes();
    s.messages = messages_.load();
    std::lock_guard<std::mutex> lock(mutex_);
    s.state = state_;
    s.error = error_;
    s.connecting = connecting_;
    for (const auto& f : files_) {
        s.files.push_back(f.path);
        s.bytes += f.size;
    }
    const auto end = (state_ == RecordingState::stopped || state_ == RecordingState::failed) ? ended_ : std::chrono::steady_clock::now();
    s.duration_s = std::chrono::duration<double>(end - started_).count();
    return s;
}

}  // namespace rr::server::record
