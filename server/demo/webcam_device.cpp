#include "server/demo/webcam_device.hpp"

#include <algorithm>

#include <boost/asio/post.hpp>

#include "robdef/builtin/experimental_createwebcam.hpp"

namespace rr::server::demo {

namespace asio = boost::asio;
using namespace std::chrono_literals;

namespace {
Unexpected gone() { return fail(MessageErrorType::ServiceNotFound, "the webcam device has shut down"); }
}  // namespace

// ---------------------------------------------------------------------------------------------------
// WebcamDevice

Result<void> WebcamDevice::setup(const std::shared_ptr<const ServiceTypes>& types) {
    auto object = ServiceObject::create(types, robdef::kExperimentalWebcamObjectType);
    if (!object) return object.take_error();
    object_ = *object;
    auto& o = *object_;
    std::weak_ptr<WebcamDevice> weak = weak_from_this();

    if (auto r = o.set_property_value("Name", Value(name_)); !r) return r;
    auto r = o.set_function("CaptureFrame", [weak](const SessionRef&, std::vector<Value>) -> Result<Value> {
        auto self = weak.lock();
        if (!self) return gone();
        return webcam_image_value(self->capture());
    });
    if (!r) return r;
    r = o.set_function("CaptureFrameToBuffer", [weak](const SessionRef&, std::vector<Value>) -> Result<Value> {
        auto self = weak.lock();
        if (!self) return gone();
        return webcam_image_size_value(self->capture_to_buffer());
    });
    if (!r) return r;
    r = o.set_function("StartStreaming", [weak](const SessionRef& session, std::vector<Value>) -> Result<Value> {
        auto self = weak.lock();
        if (!self) return gone();
        self->start_streaming(session);
        return Value();
    });
    if (!r) return r;
    r = o.set_function("StopStreaming", [weak](const SessionRef& session, std::vector<Value>) -> Result<Value> {
        auto self = weak.lock();
        if (!self) return gone();
        self->stop_streaming(session);
        return Value();
    });
    if (!r) return r;

    auto pipe = o.pipe("FrameStream");
    if (!pipe) return pipe.take_error();
    stream_ = *pipe;
    stream_->set_max_backlog_bytes(options_.max_backlog_bytes);
    auto buffer = o.memory("buffer");
    if (!buffer) return buffer.take_error();
    buffer_ = *buffer;
    auto multidim = o.memory("multidimbuffer");
    if (!multidim) return multidim.take_error();
    multidim_ = *multidim;
    capture_to_buffer();  // frame 0: the memories are never empty
    return {};
}

WebcamFrame WebcamDevice::capture() const {
    return render_webcam_frame(index_, frame_.load(), options_.width, options_.height);
}

WebcamFrame WebcamDevice::capture_to_buffer() {
    WebcamFrame f = capture();
    std::lock_guard lock(capture_mutex_);
    (void)buffer_->set_contents(Value(NumericArray::from<std::uint8_t>(std::span<const std::uint8_t>(f.data))));
    (void)multidim_->set_contents(Value(webcam_multidim(f)));
    return f;
}

void WebcamDevice::start_streaming(const SessionRef& session) {
    std::lock_guard lock(mutex_);
    std::erase(streamers_, session);
    streamers_.push_back(session);
}

void WebcamDevice::stop_streaming(const SessionRef& session) {
    std::lock_guard lock(mutex_);
    std::erase(streamers_, session);
}

bool WebcamDevice::streaming() const {
    std::lock_guard lock(mutex_);
    return std::any_of(streamers_.begin(), streamers_.end(), [](const SessionRef& s) { return s.alive(); });
}

StreamStats WebcamDevice::stats() const {
    std::lock_guard lock(mutex_);
    return stats_;
}

void WebcamDevice::next_frame() {
    const std::uint64_t number = frame_.fetch_add(1) + 1;
    {
        std::lock_guard lock(mutex_);
        std::erase_if(streamers_, [](const SessionRef& s) { return !s.alive(); });
        if (streamers_.empty()) return;
    }
    auto endpoints = stream_->endpoints();
    if (endpoints.empty()) return;
    std::uint64_t sent = 0, skipped = 0;
    std::optional<Value> image;
    for (const auto& ep : endpoints) {
        // Checked before packing too: a client that lags costs no packing work.
        if (ep->session().queued_bytes() > options_.max_backlog_bytes) {
            ++skipped;
            continue;
        }
        if (!image) image = webcam_image_value(render_webcam_frame(index_, number, options_.width, options_.height));
        auto r = ep->send(*image);
        if (r) ++sent;
        else if (r.error().type == MessageErrorType::BufferLimitViolation) ++skipped;
        // Other errors: the endpoint or its client is gone; it is dropped by the pipe member.
    }
    std::lock_guard lock(mutex_);
    stats_.frames_sent += sent;
    stats_.frames_skipped += skipped;
}

// ---------------------------------------------------------------------------------------------------
// WebcamHostDevice

WebcamHostDevice::~WebcamHostDevice() = default;

Result<std::shared_ptr<WebcamHostDevice>> WebcamHostDevice::create(WebcamOptions options) {
    if (options.frame_period <= 0ms) return fail(MessageErrorType::InvalidArgument, "webcam: frame period must be positive");
    if (options.names.empty()) return fail(MessageErrorType::InvalidArgument, "webcam: no cameras");
    auto types = ServiceTypes::create({std::string(robdef::experimental_createwebcam_robdef())});
    if (!types) return types.take_error();
    std::shared_ptr<WebcamHostDevice> host(new WebcamHostDevice(options));
    auto object = ServiceObject::create(*types, robdef::kExperimentalWebcamHostObjectType);
    if (!object) return object.take_error();
    host->object_ = *object;

    MapInt32 names;
    for (std::size_t i = 0; i < host->options_.names.size(); ++i) {
        std::shared_ptr<WebcamDevice> cam(
            new WebcamDevice(static_cast<std::int32_t>(i), host->options_.names[i], host->options_));
        if (auto r = cam->setup(*types); !r) return r.take_error();
        names.entries.emplace_back(static_cast<std::int32_t>(i), Value(host->options_.names[i]));
        host->cameras_.push_back(std::move(cam));
    }
    if (auto r = host->object_->set_property_value("WebcamNames", Value(std::move(names))); !r) return r.take_error();

    std::weak_ptr<WebcamHostDevice> weak = host;
    auto r = host->object_->set_objref(
        "Webcams", [weak](const SessionRef&, const ObjRefIndex& index) -> Result<std::shared_ptr<ServiceObject>> {
            auto self = weak.lock();
            if (!self) return gone();
            const auto* i = std::get_if<std::int32_t>(&index);
            if (!i || *i < 0 || static_cast<std::size_t>(*i) >= self->cameras_.size())
                return fail(MessageErrorType::ObjectNotFound,
                            "no webcam " + (i ? std::to_string(*i) : std::string("without index")));
            return self->cameras_[static_cast<std::size_t>(*i)]->object();
        });
    if (!r) return r.take_error();
    return host;
}

void WebcamHostDevice::tick() {
    for (const auto& c : cameras_) c->next_frame();
}

void WebcamHostDevice::start(asio::io_context& io) {
    driver_ = PeriodicTask::start(io, options_.frame_period, [weak = weak_from_this()](std::chrono::nanoseconds) {
        if (auto self = weak.lock()) self->tick();
    });
}

void WebcamHostDevice::stop() {
    if (driver_) driver_->stop();
}

}  // namespace rr::server::demo
