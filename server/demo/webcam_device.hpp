// The demo device `webcam`: `experimental.createwebcam.WebcamHost` with two simulated webcams
// (robdef/builtin/experimental_createwebcam.hpp; images: webcam_image.hpp).
//
// WebcamHost
//   WebcamNames   string{int32} {0: "Left", 1: "Right"}                                  [readonly]
//   Webcams[i]    objref Webcam{int32}: i = 0, 1; any other index → ObjectNotFound
// Webcam
//   Name                    the camera's name                                            [readonly]
//   CaptureFrame()          the current frame (WebcamImage, RGB, step = width·3)
//   StartStreaming()        the calling session starts streaming: while at least one live session
//                           streams, every frame (frame_period, 10 fps) is sent on every FrameStream
//                           pipe endpoint of every client. Backpressure: an endpoint whose client has
//                           more than max_backlog_bytes waiting gets no frame this time (counted in
//                           StreamStats::frames_skipped); sending never blocks.
//   StopStreaming()         the calling session stops streaming (a closed session stops too)
//   FrameStream             pipe WebcamImage [readonly]
//   CaptureFrameToBuffer()  renders the current frame into `buffer` (uint8[], height·step bytes, the
//                           WebcamImage data layout) and `multidimbuffer` (uint8[*], dims
//                           {height, width, 3}: [y, x, channel], channel 0 = R); returns its
//                           WebcamImage_size. Both memories hold frame 0 from the start.
//
// The frame number of each camera advances by one per tick() (start(): every frame_period in real
// time); CaptureFrame renders the current one.
//
// Threads: thread-safe; handlers hold only weak references to the devices.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "server/demo/periodic_task.hpp"
#include "server/demo/webcam_image.hpp"
#include "server/service/memory_member.hpp"
#include "server/service/pipe_member.hpp"
#include "server/service/service_object.hpp"

namespace rr::server::demo {

struct WebcamOptions {
    std::int32_t width = 320, height = 240;
    std::chrono::milliseconds frame_period{100};      ///< 10 fps
    std::size_t max_backlog_bytes = 1024 * 1024;       ///< per client, before frames are skipped
    std::vector<std::string> names = {"Left", "Right"};  ///< one camera per name
};

struct StreamStats {
    std::uint64_t frames_sent = 0;     ///< packets handed to endpoints
    std::uint64_t frames_skipped = 0;  ///< endpoint × frame pairs skipped for backpressure
};

class WebcamDevice : public std::enable_shared_from_this<WebcamDevice> {
public:
    std::int32_t index() const noexcept { return index_; }
    const std::string& name() const noexcept { return name_; }
    const std::shared_ptr<ServiceObject>& object() const noexcept { return object_; }

    std::uint64_t frame_number() const noexcept { return frame_.load(); }
    /// The current frame.
    WebcamFrame capture() const;
    /// Renders the current frame into the memories; returns it.
    WebcamFrame capture_to_buffer();
    void start_streaming(const SessionRef& session);
    void stop_streaming(const SessionRef& session);
    bool streaming() const;
    /// Advances to the next frame and, while streaming, sends it (see above).
    void next_frame();
    StreamStats stats() const;

private:
    friend class WebcamHostDevice;
    WebcamDevice(std::int32_t index, std::string name, const WebcamOptions& options)
        : index_(index), name_(std::move(name)), options_(options) {}
    Result<void> setup(const std::shared_ptr<const ServiceTypes>& types);

    const std::int32_t index_;
    const std::string name_;
    const WebcamOptions options_;
    std::shared_ptr<ServiceObject> object_;
    std::shared_ptr<PipeMember> stream_;
    std::shared_ptr<MemoryMember> buffer_, multidim_;
    std::atomic<std::uint64_t> frame_{0};
    mutable std::mutex mutex_;
    std::vector<SessionRef> streamers_;
    StreamStats stats_;
    std::mutex capture_mutex_;  // one CaptureFrameToBuffer at a time (two memories)
};

class WebcamHostDevice : public std::enable_shared_from_this<WebcamHostDevice> {
public:
    /// The host object (experimental.createwebcam.WebcamHost) and its cameras, handlers attached.
    static Result<std::shared_ptr<WebcamHostDevice>> create(WebcamOptions options = {});
    ~WebcamHostDevice();

    const std::shared_ptr<ServiceObject>& object() const noexcept { return object_; }
    const WebcamOptions& options() const noexcept { return options_; }
    std::size_t camera_count() const noexcept { return cameras_.size(); }
    /// Camera `i` (< camera_count()).
    const std::shared_ptr<WebcamDevice>& camera(std::size_t i) const { return cameras_.at(i); }

    /// Every camera's next_frame().
    void tick();
    /// Ticks in real time on `io` (every frame_period, PeriodicTask). Call once.
    void start(boost::asio::io_context& io);
    /// Stops the timer. Idempotent.
    void stop();

private:
    explicit WebcamHostDevice(WebcamOptions options) : options_(std::move(options)) {}

    const WebcamOptions options_;
    std::shared_ptr<ServiceObject> object_;
    std::vector<std::shared_ptr<WebcamDevice>> cameras_;
    std::shared_ptr<PeriodicTask> driver_;  // real time (start())
};

}  // namespace rr::server::demo
