// rr+usb state machines: the outbound scheduler, the host multiplexer and the device function, alone
// and wired back to back (a host and a device exchanging transfers in memory).
#include <catch2/catch.hpp>

#include <map>
#include <vector>

#include "base/codec/endian.hpp"
#include "base/usb/usb_device_function.hpp"
#include "base/usb/usb_host_mux.hpp"

using namespace rr;
using namespace rr::usb;

namespace {

std::vector<std::byte> pattern(std::size_t n, int seed) {
    std::vector<std::byte> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::byte>((i * 31 + seed) & 0xFF);
    return v;
}

std::vector<std::byte> data_packet(std::int32_t id, std::vector<std::byte> payload) {
    std::vector<std::byte> out(8 + payload.size());
    write_data_subpacket(out, id, payload);
    return out;
}

std::vector<std::byte> note_packet(std::int32_t id, Notification n) {
    std::vector<std::byte> out(10);
    write_notification(out, id, n);
    return out;
}

// Runs a control request against the device function.
struct Control {
    DeviceFunction& fn;
    Result<ControlOutcome> in(ControlRequest r, std::array<std::byte, 64>& buf, std::uint8_t iface = 0) {
        return fn.on_control(stream_control_request(r, iface), {}, buf);
    }
    Result<ControlOutcome> out(ControlRequest r, std::vector<std::byte> data, std::uint8_t iface = 0) {
        std::array<std::byte, 4> none{};
        return fn.on_control(stream_control_request(r, iface), data, none);
    }
};

std::vector<std::byte> le32(std::int32_t v) {
    std::vector<std::byte> b(4);
    store_le(b.data(), v);
    return b;
}

}  // namespace

TEST_CASE("usb scheduler: streams are served round-robin, one sub-packet each, large writes split") {
    SubpacketScheduler s(4);
    REQUIRE(s.add(1));
    REQUIRE(s.add(2));
    const auto a = pattern(100, 1), b = pattern(30, 2);
    REQUIRE(s.set_pending(1, a));
    REQUIRE(s.set_pending(2, b));
    CHECK_FALSE(s.set_pending(1, b));  // one write at a time
    std::array<std::byte, 48> packet{};  // 40 payload bytes per sub-packet
    std::vector<std::int32_t> order;
    std::map<std::int32_t, std::vector<std::byte>> got;
    while (auto f = s.fill(packet)) {
        auto p = parse_subpacket(std::span<const std::byte>(packet).first(f->size));
        REQUIRE(p);
        REQUIRE(p->kind == SubpacketKind::Data);
        order.push_back(p->stream_id);
        got[p->stream_id].insert(got[p->stream_id].end(), p->payload.begin(), p->payload.end());
        CHECK(f->consumed == p->payload.size());
        CHECK(f->drained == (s.pending(f->stream_id) == 0));
    }
    CHECK(order == std::vector<std::int32_t>{1, 2, 1, 1});
    CHECK(got[1] == a);
    CHECK(got[2] == b);
    CHECK_FALSE(s.has_work());
}

TEST_CASE("usb scheduler: pause, pause-all, notifications first, close after the pending data") {
    SubpacketScheduler s(2, 2);
    REQUIRE(s.add(5));
    REQUIRE(s.add(6));
    CHECK_FALSE(s.add(7));  // table full
    CHECK(s.add(7).error().type == MessageErrorType::OutOfSystemResource);
    CHECK_FALSE(s.add(5));
    const auto a = pattern(20, 3);
    REQUIRE(s.set_pending(5, a));
    s.set_paused(5, true);
    std::array<std::byte, 64> packet{};
    CHECK_FALSE(s.fill(packet));
    s.set_paused(5, false);
    s.set_all_paused(true);
    CHECK_FALSE(s.has_work());
    REQUIRE(s.queue_notification(6, Notification::PauseRequest));
    REQUIRE(s.queue_notification(6, Notification::ResumeRequest));
    CHECK_FALSE(s.queue_notification(6, Notification::PauseRequest));  // queue bound
    CHECK_FALSE(s.queue_notification(6, Notification::SocketClosed));
    auto n1 = s.fill(packet);  // notifications go even when data is paused
    REQUIRE(n1);
    CHECK(n1->notification == Notification::PauseRequest);
    auto n2 = s.fill(packet);
    REQUIRE(n2);
    CHECK(n2->notification == Notification::ResumeRequest);
    CHECK_FALSE(s.fill(packet));
    s.set_all_paused(false);
    // Close 5 while its data is pending: the data goes first, then "socket closed".
    CHECK(s.close_after_drain(5));
    CHECK_FALSE(s.set_pending(5, a));
    auto d = s.fill(packet);
    REQUIRE(d);
    CHECK(d->stream_id == 5);
    CHECK(d->consumed == 20);
    auto c = s.fill(packet);
    REQUIRE(c);
    CHECK(c->closed);
    CHECK(c->notification == Notification::SocketClosed);
    CHECK_FALSE(s.contains(5));
    CHECK(s.size() == 1);
}

TEST_CASE("usb host mux: inbound events and the two error classes") {
    HostMux m(4);
    REQUIRE(m.stream_connected(1));
    REQUIRE(m.stream_connected(2));
    CHECK_FALSE(m.stream_connected(2));

    auto data = data_packet(1, pattern(10, 0));
    auto ev = m.on_in_transfer(data);
    REQUIRE(ev);
    CHECK(ev->kind == HostEvent::Kind::Data);
    CHECK(ev->stream_id == 1);
    CHECK(ev->payload.size() == 10);

    auto zlp = m.on_in_transfer({});
    REQUIRE(zlp);
    CHECK(zlp->kind == HostEvent::Kind::Ignored);

    auto pause = m.on_in_transfer(note_packet(2, Notification::PauseRequest));
    REQUIRE(pause);
    CHECK(pause->kind == HostEvent::Kind::Paused);
    CHECK(m.out().paused(2));
    auto resume = m.on_in_transfer(note_packet(2, Notification::ResumeRequest));
    REQUIRE(resume);
    CHECK(resume->kind == HostEvent::Kind::Resumed);
    CHECK_FALSE(m.out().paused(2));

    // Unknown stream: InvalidEndpoint (drop the transfer, keep the link).
    auto unknown = m.on_in_transfer(data_packet(9, pattern(3, 0)));
    REQUIRE_FALSE(unknown);
    CHECK(unknown.error().type == MessageErrorType::InvalidEndpoint);
    CHECK(unknown.error().message.find("stream 9") != std::string::npos);
    // Malformed or a command: ProtocolError (the link is broken).
    auto bad = data_packet(1, pattern(4, 0));
    bad[0] = std::byte{100};
    auto malformed = m.on_in_transfer(bad);
    REQUIRE_FALSE(malformed);
    CHECK(malformed.error().type == MessageErrorType::ProtocolError);
    std::vector<std::byte> command(8);
    write_data_header(command, 1, 0);
    command[2] = std::byte{1};
    auto cmd = m.on_in_transfer(command);
    REQUIRE_FALSE(cmd);
    CHECK(cmd.error().type == MessageErrorType::ProtocolError);

    // The host closes 1: the device must be told; data still in flight for it is ignored quietly.
    CHECK(m.close_stream(1));
    CHECK_FALSE(m.close_stream(1));
    auto late = m.on_in_transfer(data);
    REQUIRE(late);
    CHECK(late->kind == HostEvent::Kind::Ignored);
    // The device closes 2: no CLOSE_STREAM needed afterwards.
    auto closed = m.on_in_transfer(note_packet(2, Notification::SocketClosed));
    REQUIRE(closed);
    CHECK(closed->kind == HostEvent::Kind::Closed);
    CHECK_FALSE(m.close_stream(2));
    CHECK(m.stream_count() == 0);
    // An id the device hands out again is live again.
    REQUIRE(m.stream_connected(1));
    auto again = m.on_in_transfer(data);
    REQUIRE(again);
    CHECK(again->kind == HostEvent::Kind::Data);
}

TEST_CASE("usb device function: control requests") {
    DeviceFunctionConfig cfg;
    cfg.interface_number = 2;
    cfg.max_streams = 2;
    DeviceFunction fn(cfg);
    Control c{fn};
    std::array<std::byte, 64> buf{};

    // Descriptor set through the 0xBA request: first the 8-byte header, then all of it.
    auto head = fn.on_control(descriptor_set_request(2, 8), {}, buf);
    REQUIRE(head);
    CHECK(head->in_length == 8);
    auto total = parse_descriptor_set_length(std::span<const std::byte>(buf).first(8));
    REQUIRE(total);
    auto whole = fn.on_control(descriptor_set_request(2, *total), {}, buf);
    REQUIRE(whole);
    auto set = parse_descriptor_set(std::span<const std::byte>(buf).first(whole->in_length));
    REQUIRE(set);
    CHECK(set->node_id_string == cfg.node_id_string);
    CHECK(set->supports_stream_protocol());

    CHECK_FALSE(fn.accepts(stream_control_request(ControlRequest::ConnectStream, 0)));  // another interface
    CHECK_FALSE(fn.on_control(stream_control_request(ControlRequest::ConnectStream, 0), {}, buf));

    auto proto = c.out(ControlRequest::CurrentProtocol, {std::byte{0x01}, std::byte{0x01}}, 2);
    REQUIRE(proto);
    CHECK(proto->effect == ControlOutcome::Effect::ProtocolSelected);
    CHECK(fn.protocol_selected());
    CHECK_FALSE(c.out(ControlRequest::CurrentProtocol, {std::byte{0x02}, std::byte{0x01}}, 2));

    auto s1 = c.in(ControlRequest::ConnectStream, buf, 2);
    REQUIRE(s1);
    CHECK(s1->effect == ControlOutcome::Effect::StreamOpened);
    CHECK(s1->in_length == 4);
    CHECK(load_le<std::int32_t>(buf.data()) == s1->stream_id);
    CHECK(s1->stream_id == 1);
    auto s2 = c.in(ControlRequest::ConnectStream, buf, 2);
    REQUIRE(s2);
    CHECK(s2->stream_id == 2);
    auto refused = c.in(ControlRequest::ConnectStream, buf, 2);  // max_streams 2
    REQUIRE(refused);
    CHECK(refused->effect == ControlOutcome::Effect::None);
    CHECK(load_le<std::int32_t>(buf.data()) == -1);

    auto close = c.out(ControlRequest::CloseStream, le32(1), 2);
    REQUIRE(close);
    CHECK(close->effect == ControlOutcome::Effect::StreamClosed);
    CHECK(close->stream_id == 1);
    CHECK_FALSE(c.out(ControlRequest::CloseStream, le32(1), 2));      // not open any more
    CHECK_FALSE(c.out(ControlRequest::CloseStream, {std::byte{1}}, 2));  // short data stage
    auto s3 = c.in(ControlRequest::ConnectStream, buf, 2);
    REQUIRE(s3);
    CHECK(s3->stream_id == 3);  // ids are not reused at once

    auto pause = c.in(ControlRequest::PauseAllStream, buf, 2);
    REQUIRE(pause);
    CHECK(pause->effect == ControlOutcome::Effect::PausedAll);
    CHECK(fn.host_paused_all());
    REQUIRE(c.in(ControlRequest::ResumeAllStream, buf, 2));
    CHECK_FALSE(fn.host_paused_all());

    auto reset = c.in(ControlRequest::ResetAllStream, buf, 2);
    REQUIRE(reset);
    CHECK(reset->effect == ControlOutcome::Effect::AllReset);
    CHECK(reset->in_length == 4);
    CHECK(fn.stream_count() == 0);

    // Wrong direction, unknown request.
    SetupPacket wrong = stream_control_request(ControlRequest::ConnectStream, 2);
    wrong.request_type = kVendorInterfaceOut;
    CHECK_FALSE(fn.on_control(wrong, {}, buf));
    SetupPacket unknown{kVendorInterfaceIn, 0x55, 0, 2, 4};
    auto u = fn.on_control(unknown, {}, buf);
    REQUIRE_FALSE(u);
    CHECK(u.error().type == MessageErrorType::NotImplementedError);
}

TEST_CASE("usb device function: bulk OUT events and errors") {
    DeviceFunction fn;
    std::array<std::byte, 64> buf{};
    auto s = fn.on_control(stream_control_request(ControlRequest::ConnectStream, 0), {}, buf);
    REQUIRE(s);
    const auto id = s->stream_id;
    auto ev = fn.on_bulk_out(data_packet(id, pattern(5, 1)));
    REQUIRE(ev);
    CHECK(ev->kind == DeviceEvent::Kind::Data);
    CHECK(ev->payload.size() == 5);
    auto unknown = fn.on_bulk_out(data_packet(id + 10, pattern(5, 1)));
    REQUIRE_FALSE(unknown);
    CHECK(unknown.error().type == MessageErrorType::InvalidEndpoint);
    auto zlp = fn.on_bulk_out({});
    REQUIRE(zlp);
    CHECK(zlp->kind == DeviceEvent::Kind::Ignored);
    // The device asks the host to pause and resume: notifications out.
    REQUIRE(fn.pause_receive(id, true));
    auto n = fn.fill_bulk_in(buf);
    REQUIRE(n);
    CHECK(n->notification == Notification::PauseRequest);
    CHECK_FALSE(fn.pause_receive(99, true));
    auto closed = fn.on_bulk_out(note_packet(id, Notification::SocketClosed));
    REQUIRE(closed);
    CHECK(closed->kind == DeviceEvent::Kind::Closed);
    CHECK_FALSE(fn.is_open(id));
}

TEST_CASE("usb: host and device back to back: several streams, large messages over small packets") {
    constexpr std::size_t kPacket = 64;  // a full-speed bulk endpoint
    HostMux host(8);
    DeviceFunction device;
    std::array<std::byte, 64> ctl{};
    std::vector<std::int32_t> ids;
    for (int i = 0; i < 3; ++i) {
        auto o = device.on_control(stream_control_request(ControlRequest::ConnectStream, 0), {}, ctl);
        REQUIRE(o);
        REQUIRE(o->effect == ControlOutcome::Effect::StreamOpened);
        REQUIRE(host.stream_connected(load_le<std::int32_t>(ctl.data())));
        ids.push_back(o->stream_id);
    }
    std::map<std::int32_t, std::vector<std::byte>> sent_up, sent_down, got_up, got_down;
    for (auto id : ids) {
        sent_down[id] = pattern(5000 + 1000 * id, id);  // host → device
        sent_up[id] = pattern(7000 - 1000 * id, 50 + id);  // device → host
        REQUIRE(host.out().set_pending(id, sent_down[id]));
        REQUIRE(device.send(id, sent_up[id]));
    }
    std::array<std::byte, kPacket> packet{};
    std::size_t transfers = 0;
    for (bool progress = true; progress;) {
        progress = false;
        if (auto f = host.out().fill(packet)) {
            progress = true;
            ++transfers;
            CHECK(f->size <= kPacket);
            auto ev = device.on_bulk_out(std::span<const std::byte>(packet).first(f->size));
            REQUIRE(ev);
            REQUIRE(ev->kind == DeviceEvent::Kind::Data);
            got_down[ev->stream_id].insert(got_down[ev->stream_id].end(), ev->payload.begin(), ev->payload.end());
        }
        if (auto f = device.fill_bulk_in(packet)) {
            progress = true;
            ++transfers;
            auto ev = host.on_in_transfer(std::span<const std::byte>(packet).first(f->size));
            REQUIRE(ev);
            REQUIRE(ev->kind == HostEvent::Kind::Data);
            got_up[ev->stream_id].insert(got_up[ev->stream_id].end(), ev->payload.begin(), ev->payload.end());
        }
    }
    CHECK(got_down == sent_down);
    CHECK(got_up == sent_up);
    // Every sub-packet but each message's last is full: 56 payload bytes under the 8-byte header.
    std::size_t expected = 0;
    for (auto* m : {&sent_up, &sent_down})
        for (const auto& [id, v] : *m) expected += (v.size() + 55) / 56;
    CHECK(transfers == expected);

    // The device closes a stream after its last bytes; the host sees the data, then the close.
    const auto last = pattern(100, 9);
    REQUIRE(device.send(ids[0], last));
    REQUIRE(device.close_stream(ids[0]));
    std::vector<HostEvent::Kind> kinds;
    while (auto f = device.fill_bulk_in(packet)) {
        auto ev = host.on_in_transfer(std::span<const std::byte>(packet).first(f->size));
        REQUIRE(ev);
        kinds.push_back(ev->kind);
    }
    CHECK(kinds == std::vector<HostEvent::Kind>{HostEvent::Kind::Data, HostEvent::Kind::Data, HostEvent::Kind::Closed});
    CHECK_FALSE(host.is_open(ids[0]));
    CHECK(host.is_open(ids[1]));
}
