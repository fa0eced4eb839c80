#include "server/transport/usb/usb_host_link.hpp"

#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>

#include "base/codec/endian.hpp"

namespace rr::server::usb {

namespace asio = boost::asio;
using rr::usb::ControlRequest;
using rr::usb::HostEvent;
using rr::usb::stream_control_request;

std::shared_ptr<UsbHostLink> UsbHostLink::create(asio::any_io_executor executor, std::shared_ptr<LibusbContext> usb,
                                                 DeviceRef device, LinkEndpoints endpoints, LinkOptions options,
                                                 std::string describe) {
    return std::shared_ptr<UsbHostLink>(new UsbHostLink(std::move(executor), std::move(usb), std::move(device), endpoints,
                                                        options, std::move(describe)));
}

UsbHostLink::UsbHostLink(asio::any_io_executor executor, std::shared_ptr<LibusbContext> usb, DeviceRef device,
                         LinkEndpoints endpoints, LinkOptions options, std::string describe)
    : strand_(asio::make_strand(std::move(executor))),
      usb_(std::move(usb)),
      device_(std::move(device)),
      ep_(endpoints),
      options_(options),
      describe_(std::move(describe)),
      mux_(options.max_streams) {}

UsbHostLink::~UsbHostLink() {
    // Transfers hold a reference to the link while in flight, so none is pending here.
    if (handle_ && claimed_) libusb_release_interface(handle_.get(), ep_.interface_number);
}

RRError UsbHostLink::link_error(std::string what) const {
    return make_error(MessageErrorType::ConnectionError, describe_ + ": " + std::move(what));
}

void UsbHostLink::set_closed_handler(ClosedHandler handler) {
    asio::dispatch(strand_, [self = shared_from_this(), h = std::move(handler)]() mutable { self->on_closed_ = std::move(h); });
}

// --- connect ------------------------------------------------------------------------------------------------

void UsbHostLink::connect_stream(asio::any_io_executor stream_executor, StreamDone done) {
    asio::post(strand_, [self = shared_from_this(), c = Connect{std::move(stream_executor), std::move(done)}]() mutable {
        switch (self->state_) {
            case State::Idle:
                self->queued_.push_back(std::move(c));
                self->claim();
                return;
            case State::Claiming:
            case State::Closing:  // retried on a new link once this one is closed
                self->queued_.push_back(std::move(c));
                return;
            case State::Ready:
                self->connect_one(std::move(c));
                return;
            case State::Closed:
                break;
        }
        if (!self->failure_ && self->on_closed_) {  // released a moment ago: the manager claims anew
            std::vector<std::pair<asio::any_io_executor, StreamDone>> retry;
            retry.emplace_back(std::move(c.executor), std::move(c.done));
            return self->on_closed_(std::move(retry));
        }
        if (self->failure_)
            c.done(rr::fail(self->link_error(self->failure_text_)));
        else
            c.done(rr::fail(self->link_error("link closed")));
    });
}

void UsbHostLink::claim() {
    state_ = State::Claiming;
    libusb_device_handle* h = nullptr;
    int r = libusb_open(device_.get(), &h);
    if (r == LIBUSB_ERROR_ACCESS) {
        auto e = link_error("permission denied");
        e.type = MessageErrorType::SystemResourcePermissionDenied;
        e.message += " (" + libusb_error_text(r) + "); see docs/usb.md for the udev rule " + kUdevRuleFile;
        return claim_failed(std::move(e));
    }
    if (r != 0) return claim_failed(link_error("cannot open: " + libusb_error_text(r)));
    handle_.reset(h);
    (void)libusb_set_auto_detach_kernel_driver(h, 1);  // not supported everywhere; harmless
    int current = 0;
    if (libusb_get_configuration(h, &current) == 0 && current != ep_.configuration && ep_.configuration > 0)
        (void)libusb_set_configuration(h, ep_.configuration);
    r = libusb_claim_interface(h, ep_.interface_number);
    if (r == LIBUSB_ERROR_BUSY)
        return claim_failed(link_error("interface " + std::to_string(ep_.interface_number) +
                                       " is claimed by another program or driver"));
    if (r != 0) return claim_failed(link_error("cannot claim interface " + std::to_string(ep_.interface_number) + ": " + libusb_error_text(r)));
    claimed_ = true;
    for (std::size_t i = 0; i < options_.in_transfers; ++i)
        in_.push_back(std::make_unique<BulkTransfer>(h, ep_.in_endpoint, ep_.in_packet_size));
    for (std::size_t i = 0; i < options_.out_transfers; ++i)
        out_.push_back(std::make_unique<BulkTransfer>(h, ep_.out_endpoint, ep_.out_packet_size));
    out_busy_.assign(out_.size(), false);
    control(stream_control_request(ControlRequest::ResetAllStream, ep_.interface_number), {},
            [self = shared_from_this()](TransferResult r, std::vector<std::byte> data) { self->after_reset(r, std::move(data)); });
}

void UsbHostLink::claim_failed(RRError error) {
    failure_ = make_error_code(usb_errc::device_io_error);
    failure_text_ = error.message;
    auto queued = std::move(queued_);
    queued_.clear();
    for (auto& c : queued) c.done(rr::fail(error));
    state_ = State::Closing;
    maybe_finish();
}

void UsbHostLink::after_reset(TransferResult r, std::vector<std::byte> data) {
    if (state_ != State::Claiming) return maybe_finish();
    if (!r.ok() || data.size() != 4)
        return claim_failed(link_error("RESET_ALL_STREAM failed: " + (r.ok() ? std::to_string(data.size()) + " bytes answered (4 expected)" : r.text())));
    // A zero-length bulk OUT (as CORE), then the protocol selection.
    ++ops_in_flight_;
    out_busy_[0] = true;
    out_[0]->submit(0, [self = shared_from_this()](TransferResult zr) {
        asio::post(self->strand_, [self, zr] {
            --self->ops_in_flight_;
            self->out_busy_[0] = false;
            if (self->state_ != State::Claiming) return self->maybe_finish();
            if (zr.device_gone()) return self->claim_failed(self->link_error("device gone during the claim"));
            std::vector<std::byte> proto(2);
            store_le(proto.data(), rr::usb::kStreamProtocol);
            self->control(stream_control_request(ControlRequest::CurrentProtocol, self->ep_.interface_number), std::move(proto),
                          [self](TransferResult pr, std::vector<std::byte>) {
                              if (self->state_ != State::Claiming) return self->maybe_finish();
                              if (!pr.ok())
                                  return self->claim_failed(self->link_error("CURRENT_PROTOCOL 0x0101 refused: " + pr.text()));
                              self->ready();
                          });
        });
    });
}

void UsbHostLink::ready() {
    state_ = State::Ready;
    for (std::size_t i = 0; i < in_.size(); ++i) submit_in(i);
    run_connects();
}

void UsbHostLink::run_connects() {
    auto queued = std::move(queued_);
    queued_.clear();
    for (auto& c : queued) connect_one(std::move(c));
}

void UsbHostLink::connect_one(Connect c) {
    ++connects_in_flight_;
    control(stream_control_request(ControlRequest::ConnectStream, ep_.interface_number), {},
            [self = shared_from_this(), c = std::move(c)](TransferResult r, std::vector<std::byte> data) mutable {
                --self->connects_in_flight_;
                if (self->state_ != State::Ready) {
                    c.done(rr::fail(self->link_error(self->failure_ ? self->failure_text_ : std::string("link closed"))));
                    return self->maybe_release();
                }
                if (!r.ok() || data.size() != 4) {
                    c.done(rr::fail(self->link_error("CONNECT_STREAM failed: " + (r.ok() ? std::to_string(data.size()) + " bytes answered (4 expected)" : r.text()))));
                    return self->maybe_release();
                }
                const auto id = load_le<std::int32_t>(data.data());
                if (id < 0) {
                    c.done(rr::fail(self->link_error("the device refused the stream (CONNECT_STREAM answered " + std::to_string(id) + ")")));
                    return self->maybe_release();
                }
                if (auto ok = self->mux_.stream_connected(id); !ok) {
                    c.done(rr::fail(self->link_error("CONNECT_STREAM answered stream " + std::to_string(id) + ": " + ok.error().message)));
                    return self->maybe_release();
                }
                self->streams_.try_emplace(id);
                self->stream_count_.store(self->streams_.size());
                self->stats_.streams_opened.fetch_add(1);
                c.done(UsbByteStream(c.executor, self, id));
            });
}

void UsbHostLink::control(const rr::usb::SetupPacket& setup, std::vector<std::byte> out_data,
                          std::function<void(TransferResult, std::vector<std::byte>)> done) {
    if (!handle_ || state_ == State::Closed) return done(TransferResult{LIBUSB_ERROR_NO_DEVICE, 0}, {});
    ++ops_in_flight_;
    submit_control(handle_.get(), setup, out_data, options_.control_timeout_ms,
                   [self = shared_from_this(), done = std::move(done)](TransferResult r, std::vector<std::byte> data) mutable {
                       asio::post(self->strand_, [self, done = std::move(done), r, data = std::move(data)]() mutable {
                           --self->ops_in_flight_;
                           done(r, std::move(data));
                       });
                   });
}

// --- bulk IN -------------------------------------------------------------------------------------------------

void UsbHostLink::submit_in(std::size_t index) {
    ++ops_in_flight_;
    in_[index]->submit(in_[index]->buffer().size(), [self = shared_from_this(), index](TransferResult r) {
        asio::post(self->strand_, [self, index, r] { self->on_in(index, r); });
    });
}

void UsbHostLink::on_in(std::size_t index, TransferResult r) {
    --ops_in_flight_;
    if (state_ != State::Ready) return maybe_finish();
    if (!r.ok()) return transfer_failed(r, "bulk IN");
    stats_.in_transfers.fetch_add(1, std::memory_order_relaxed);
    dispatch(in_[index]->received(r.actual));
    if (state_ == State::Ready) submit_in(index);
    else maybe_finish();
}

void UsbHostLink::dispatch(std::span<const std::byte> transfer) {
    auto ev = mux_.on_in_transfer(transfer);
    if (!ev) {
        if (ev.error().type == MessageErrorType::InvalidEndpoint) {
            stats_.dropped_unknown_stream.fetch_add(1);
            return;
        }
        return fail_now(make_error_code(usb_errc::protocol_error), ev.error().message);
    }
    switch (ev->kind) {
        case HostEvent::Kind::Ignored:
            return;
        case HostEvent::Kind::Data: {
            auto it = streams_.find(ev->stream_id);
            if (it != streams_.end()) it->second.on_data(ev->payload);
            return check_rx_flow();
        }
        case HostEvent::Kind::Closed: {
            auto it = streams_.find(ev->stream_id);
            if (it != streams_.end()) it->second.end(asio::error::eof, asio::error::broken_pipe);
            return;
        }
        case HostEvent::Kind::Paused:
            stats_.device_pause_requests.fetch_add(1);
            return;
        case HostEvent::Kind::Resumed:
            stats_.device_resume_requests.fetch_add(1);
            return pump_out();
    }
}

void UsbHostLink::check_rx_flow() {
    std::size_t queued = 0;
    for (const auto& [id, s] : streams_) queued += s.queued();
    const bool pause = !rx_paused_ && queued > options_.rx_high_water;
    const bool resume = rx_paused_ && queued < options_.rx_low_water;
    if (!pause && !resume) return;
    rx_paused_ = pause;
    (pause ? stats_.pause_all_sent : stats_.resume_all_sent).fetch_add(1);
    control(stream_control_request(pause ? ControlRequest::PauseAllStream : ControlRequest::ResumeAllStream, ep_.interface_number),
            {}, [self = shared_from_this()](TransferResult, std::vector<std::byte>) { self->maybe_finish(); });
}

// --- bulk OUT ------------------------------------------------------------------------------------------------

void UsbHostLink::pump_out() {
    if (state_ != State::Ready) return;
    for (std::size_t i = 0; i < out_.size() && mux_.out().has_work(); ++i) {
        if (out_busy_[i]) continue;
        auto f = mux_.out().fill(out_[i]->buffer());
        if (!f) break;
        if (f->drained) {
            auto it = streams_.find(f->stream_id);
            if (it != streams_.end()) it->second.write_drained();
        }
        out_busy_[i] = true;
        ++ops_in_flight_;
        out_[i]->submit(f->size, [self = shared_from_this(), i](TransferResult r) {
            asio::post(self->strand_, [self, i, r] { self->on_out(i, r); });
        });
    }
}

void UsbHostLink::on_out(std::size_t index, TransferResult r) {
    --ops_in_flight_;
    out_busy_[index] = false;
    if (state_ != State::Ready) return maybe_finish();
    if (!r.ok()) return transfer_failed(r, "bulk OUT");
    stats_.out_transfers.fetch_add(1, std::memory_order_relaxed);
    pump_out();
}

void UsbHostLink::transfer_failed(const TransferResult& r, const char* what) {
    if (r.device_gone()) return fail_now(make_error_code(usb_errc::device_unplugged), "the device was unplugged");
    if (r.status == LIBUSB_TRANSFER_CANCELLED) return maybe_finish();
    fail_now(make_error_code(usb_errc::device_io_error), std::string(what) + " transfer failed: " + r.text());
}

// --- stream operations -------------------------------------------------------------------------------------

void UsbHostLink::async_read(std::int32_t id, asio::mutable_buffer buffer, StreamCompletion done) {
    asio::dispatch(strand_, [self = shared_from_this(), id, buffer, done = std::move(done)]() mutable {
        auto it = self->streams_.find(id);
        if (it == self->streams_.end())
            return done(self->failure_ ? self->failure_ : asio::error::make_error_code(asio::error::not_connected), 0);
        it->second.start_read(buffer, std::move(done));
        if (self->rx_paused_ && self->state_ == State::Ready) self->check_rx_flow();
    });
}

void UsbHostLink::async_write(std::int32_t id, asio::const_buffer buffer, StreamCompletion done) {
    asio::dispatch(strand_, [self = shared_from_this(), id, buffer, done = std::move(done)]() mutable {
        auto it = self->streams_.find(id);
        if (it == self->streams_.end())
            return done(self->failure_ ? self->failure_ : asio::error::make_error_code(asio::error::not_connected), 0);
        if (self->state_ != State::Ready || !self->mux_.is_open(id))
            return done(self->failure_ ? self->failure_ : asio::error::make_error_code(asio::error::broken_pipe), 0);
        auto set = self->mux_.out().set_pending(id, std::span<const std::byte>(static_cast<const std::byte*>(buffer.data()), buffer.size()));
        if (!set) return done(asio::error::make_error_code(asio::error::in_progress), 0);
        it->second.start_write(buffer.size(), std::move(done));
        self->pump_out();
    });
}

void UsbHostLink::close_stream(std::int32_t id) {
    asio::post(strand_, [self = shared_from_this(), id] {
        auto it = self->streams_.find(id);
        if (it == self->streams_.end()) return;
        self->mux_.out().drop_pending(id);
        it->second.abort(asio::error::operation_aborted);
        self->streams_.erase(it);
        self->stream_count_.store(self->streams_.size());
        if (self->mux_.close_stream(id) && self->state_ == State::Ready) {
            std::vector<std::byte> data(4);
            store_le(data.data(), id);
            self->control(stream_control_request(ControlRequest::CloseStream, self->ep_.interface_number), std::move(data),
                          [self](TransferResult, std::vector<std::byte>) { self->maybe_release(); });
            return;
        }
        self->maybe_release();
    });
}

// --- closing -------------------------------------------------------------------------------------------------

void UsbHostLink::maybe_release() {
    if (state_ == State::Ready && streams_.empty() && connects_in_flight_ == 0 && queued_.empty()) return begin_release();
    maybe_finish();
}

void UsbHostLink::begin_release() {
    state_ = State::Closing;
    mux_.reset();
    control(stream_control_request(ControlRequest::ResetAllStream, ep_.interface_number), {},
            [self = shared_from_this()](TransferResult, std::vector<std::byte>) {
                for (auto& t : self->in_) t->cancel();
                for (auto& t : self->out_) t->cancel();
                self->maybe_finish();
            });
}

void UsbHostLink::fail(boost::system::error_code ec, std::string why) {
    asio::post(strand_, [self = shared_from_this(), ec, why = std::move(why)]() mutable { self->fail_now(ec, std::move(why)); });
}

void UsbHostLink::fail_now(boost::system::error_code ec, std::string why) {
    if (state_ == State::Closed || failure_) return;
    failure_ = ec;
    failure_text_ = why;
    state_ = State::Closing;
    mux_.reset();
    for (auto& [id, s] : streams_) s.abort(ec);
    auto queued = std::move(queued_);
    queued_.clear();
    for (auto& c : queued) c.done(rr::fail(link_error(why)));
    for (auto& t : in_) t->cancel();
    for (auto& t : out_) t->cancel();
    maybe_finish();
}

void UsbHostLink::maybe_finish() {
    if (state_ == State::Closing && ops_in_flight_ == 0) finish();
}

void UsbHostLink::finish() {
    state_ = State::Closed;
    if (handle_) {
        if (claimed_) libusb_release_interface(handle_.get(), ep_.interface_number);
        claimed_ = false;
        in_.clear();
        out_.clear();
        handle_.reset();
    }
    for (auto& [id, s] : streams_) s.abort(failure_ ? failure_ : make_error_code(usb_errc::link_closed));
    closed_flag_.store(true);
    std::vector<std::pair<asio::any_io_executor, StreamDone>> retry;
    for (auto& c : queued_) retry.emplace_back(std::move(c.executor), std::move(c.done));
    queued_.clear();
    if (on_closed_) {
        on_closed_(std::move(retry));
    } else {
        for (auto& [ex, done] : retry) done(rr::fail(link_error("link closed")));
    }
}

}  // namespace rr::server::usb
