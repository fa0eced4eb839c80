// rr+usb host pieces that need no device: URL rules, the stream's byte queues, error texts, and the
// host on a bus without RR devices. The emulated device tests (real libusb against umockdev) are in
// test/usb.
#include <catch2/catch.hpp>

#include <exception>
#include <future>

#include <boost/asio/io_context.hpp>
#include <boost/asio/strand.hpp>

#include "server/transport/usb/usb_host.hpp"
#include "test/support/skip.hpp"

using namespace rr;
using namespace rr::server::usb;
using namespace std::chrono_literals;

namespace {

ConnectionUrl url(std::string_view text) {
    auto u = parse_connection_url(text);
    INFO(text);
    REQUIRE(u);
    return *u;
}

struct Collected {
    boost::system::error_code ec;
    std::size_t n = 0;
    bool called = false;
};

StreamCompletion collect(Collected& c) {
    return StreamCompletion([&c](boost::system::error_code ec, std::size_t n) {
        c.ec = ec;
        c.n = n;
        c.called = true;
    });
}

std::vector<std::byte> text(std::string_view s) {
    std::vector<std::byte> v(s.size());
    std::transform(s.begin(), s.end(), v.begin(), [](char c) { return static_cast<std::byte>(c); });
    return v;
}

}  // namespace

TEST_CASE("usb host: rr+usb URLs as CORE checks them") {
    CHECK(check_usb_url(url("rr+usb:///?nodename=board&service=svc")));
    CHECK(check_usb_url(url("rr+usb://localhost/?nodeid=6f1b1f3c-2f4e-4a1e-9d6c-0123456789ab&service=svc")));
    auto anonymous = check_usb_url(url("rr+usb:///?service=svc"));
    REQUIRE_FALSE(anonymous);
    CHECK(anonymous.error().message.find("nodeid and/or nodename") != std::string::npos);
    CHECK_FALSE(check_usb_url(url("rr+usb://otherhost/?nodename=board&service=svc")));
    CHECK_FALSE(check_usb_url(url("rr+usb://localhost:5/?nodename=board&service=svc")));
    CHECK_FALSE(check_usb_url(url("rr+tcp://localhost:5/?nodename=board&service=svc")));

    const auto id = NodeID::parse("6f1b1f3c-2f4e-4a1e-9d6c-0123456789ab").value();
    CHECK(usb_url(id, "RobotRaconteurServiceIndex") ==
          "rr+usb:///?nodeid=6f1b1f3c-2f4e-4a1e-9d6c-0123456789ab&service=RobotRaconteurServiceIndex");
    UsbDeviceInfo info;
    info.node_id = id;
    info.node_name = "board";
    CHECK(usb_url_matches(url("rr+usb:///?nodename=board&service=s"), info));
    CHECK(usb_url_matches(url(usb_url(id, "s")), info));
    CHECK(usb_url_matches(url("rr+usb:///?nodeid=6f1b1f3c-2f4e-4a1e-9d6c-0123456789ab&nodename=board&service=s"), info));
    CHECK_FALSE(usb_url_matches(url("rr+usb:///?nodeid=6f1b1f3c-2f4e-4a1e-9d6c-0123456789ab&nodename=other&service=s"), info));
    CHECK_FALSE(usb_url_matches(url("rr+usb:///?nodename=other&service=s"), info));
    info.error = make_error(MessageErrorType::SystemResourcePermissionDenied, "no");
    CHECK_FALSE(usb_url_matches(url("rr+usb:///?nodename=board&service=s"), info));
}

TEST_CASE("usb host: a stream's byte queues hand bytes to reads in order and end cleanly") {
    UsbStreamBuffers b;
    std::array<std::byte, 4> small{};
    Collected r1;
    b.start_read(boost::asio::buffer(small), collect(r1));
    CHECK_FALSE(r1.called);  // nothing yet
    const auto hello = text("hello world");
    b.on_data(hello);  // the pending read takes 4, 7 stay queued
    REQUIRE(r1.called);
    CHECK(r1.n == 4);
    CHECK(std::string(reinterpret_cast<const char*>(small.data()), 4) == "hell");
    CHECK(b.queued() == 7);
    std::array<std::byte, 64> big{};
    Collected r2;
    b.start_read(boost::asio::buffer(big), collect(r2));
    REQUIRE(r2.called);
    CHECK(r2.n == 7);
    CHECK(std::string(reinterpret_cast<const char*>(big.data()), 7) == "o world");

    // A peer close: queued bytes are still read, then eof; a pending write fails at once.
    b.on_data(text("tail"));
    Collected w;
    b.start_write(10, collect(w));
    b.end(boost::asio::error::eof, boost::asio::error::broken_pipe);
    CHECK(w.ec == boost::asio::error::broken_pipe);
    Collected r3, r4;
    b.start_read(boost::asio::buffer(big), collect(r3));
    CHECK(r3.n == 4);
    CHECK_FALSE(r3.ec);
    b.start_read(boost::asio::buffer(big), collect(r4));
    CHECK(r4.ec == boost::asio::error::eof);

    // A write completes with its full size once drained; abort drops queued bytes.
    UsbStreamBuffers c;
    Collected w2;
    c.start_write(123, collect(w2));
    CHECK(c.write_pending());
    c.write_drained();
    CHECK(w2.n == 123);
    c.on_data(text("dropped"));
    Collected r5;
    c.abort(make_error_code(usb_errc::device_unplugged));
    c.start_read(boost::asio::buffer(big), collect(r5));
    CHECK(r5.ec == make_error_code(usb_errc::device_unplugged));
    CHECK(r5.ec.message() == "USB device was unplugged");
}

TEST_CASE("usb host: a closed UsbByteStream completes operations with bad_descriptor on its executor") {
    boost::asio::io_context io;
    UsbByteStream s(io.get_executor(), nullptr, 1);
    boost::system::error_code got;
    bool called = false;
    std::array<std::byte, 8> buf{};
    s.async_read_some(boost::asio::buffer(buf), [&](boost::system::error_code ec, std::size_t) {
        got = ec;
        called = true;
    });
    CHECK_FALSE(called);  // posted, not run inline
    io.run();
    CHECK(called);
    CHECK(got == boost::asio::error::bad_descriptor);
}

TEST_CASE("usb host: permission errors name the udev rule") {
    auto e = permission_error(0x1209, 0x0001, "/dev/bus/usb/001/002");
    CHECK(e.type == MessageErrorType::SystemResourcePermissionDenied);
    CHECK(e.message.find("1209:0001") != std::string::npos);
    CHECK(e.message.find("/dev/bus/usb/001/002") != std::string::npos);
    CHECK(e.message.find("gateway-config/70-robotraconteur-usb.rules") != std::string::npos);
}

TEST_CASE("usb host: on a bus without RR devices enumerate is empty and connect says no device") {
    boost::asio::io_context io;
    UsbHostOptions o;
    o.sysfs_root = "/nonexistent";
    auto host = UsbHost::create(io.get_executor(), o);
    if (!host) RR_SKIP("libusb cannot start here: " << host.error().message);
    auto work = boost::asio::make_work_guard(io);
    std::thread t([&] { io.run(); });
    struct Joiner {  // a failed REQUIRE (an exception) must not leave the thread joinable, nor wait on the host
        boost::asio::io_context& io;
        boost::asio::executor_work_guard<boost::asio::io_context::executor_type>& work;
        std::thread& t;
        ~Joiner() {
            work.reset();
            if (std::uncaught_exceptions() > 0) io.stop();
            t.join();
        }
    } joiner{io, work, t};
    auto devices = (*host)->enumerate_wait(30s);
    REQUIRE(devices);
    CHECK(devices->empty());
    std::promise<Result<UsbByteStream>> p;
    (*host)->open_stream(url("rr+usb:///?nodename=nobody&service=s"), io.get_executor(),
                         [&](Result<UsbByteStream> r) { p.set_value(std::move(r)); });
    auto f = p.get_future();
    REQUIRE(f.wait_for(30s) == std::future_status::ready);
    auto r = f.get();
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::ConnectionError);
    CHECK(r.error().message.find("no rr+usb device with NodeName \"nobody\" is attached") != std::string::npos);
    (*host)->shutdown();
    host->reset();
}
