// A Robot Raconteur client in C++ with the project's client library (server/client/client.hpp):
// connect to a service by URL, read a property, call a function, read a wire, handle errors.
// Runs against the demo device `create` (experimental.create.Create) of rr-gateway or rr-demo-devices:
//
//   rr-gateway &                                   # demo devices on, port 8080
//   rr_example_client 'rr+tcp://127.0.0.1:8080/?service=create'
//   rr_example_client 'rr+ws://127.0.0.1:8080/?service=create'   # the same over a WebSocket
//
// Exit status: 0 when every step worked, 1 with the RR error otherwise.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <thread>

#include "server/client/client.hpp"

using namespace std::chrono_literals;
using rr::Value;

namespace {

// Every call returns Result<T>: a value, or an RRError (name, message, MessageErrorType).
int fail(const char* step, const rr::RRError& e) {
    std::fprintf(stderr, "%s failed: %s: %s\n", step, e.name.c_str(), e.message.c_str());
    return 1;
}

}  // namespace

int main(int argc, char** argv) {
    const std::string url = argc > 1 ? argv[1] : "rr+tcp://127.0.0.1:8080/?service=create";

    // Worker threads for the connection (a program with its own io_context passes its executor).
    rr::client::IoThreads io(1);
    rr::client::ClientOptions options;
    options.request_timeout = 10s;
    auto client = rr::client::Client::connect(io.executor(), url, options);
    if (!client) return fail("connect", client.error());
    auto root = (*client)->root();
    std::printf("connected to %s: %s\n", url.c_str(), root.type().c_str());

    // A property: int32 DistanceTraveled [readonly]
    auto distance = root.get("DistanceTraveled");
    if (!distance) return fail("get DistanceTraveled", distance.error());
    std::printf("DistanceTraveled = %d mm\n", *distance->as<std::int32_t>());

    // A function: void Drive(int16 velocity, int16 radius); values carry their RR type.
    auto drive = root.call("Drive", {Value::scalar<std::int16_t>(200), Value::scalar<std::int16_t>(32767)});
    if (!drive) return fail("call Drive", drive.error());
    std::printf("Drive(200, 32767): ok\n");

    // A wrong call is an error, not a crash: Drive takes two int16 arguments.
    auto wrong = root.call("Drive", {Value::scalar(1.5)});
    if (wrong) return fail("call Drive(1.5)", rr::make_error(rr::MessageErrorType::OperationFailed, "accepted a bad call"));
    std::printf("Drive(1.5): %s (as expected)\n", wrong.error().name.c_str());

    // A wire: SensorPacket packets [readonly]; peek once, then connect, ask the device to stream and
    // wait for a new InValue (after = the values received so far: only one that arrives later).
    auto peek = root.peek_in_value("packets");
    if (!peek) return fail("peek packets", peek.error());
    auto wire = root.wire_connect("packets");
    if (!wire) return fail("connect packets", wire.error());
    if (auto r = root.call("StartStreaming"); !r) return fail("call StartStreaming", r.error());
    auto next = wire->wait_value([](const rr::WireValue&) { return true; }, 5s, wire->values_received());
    if (!next) return fail("wait for packets", next.error());
    if (auto r = root.call("StopStreaming"); !r) return fail("call StopStreaming", r.error());
    const Value* id = next->value.field("ID");
    const Value* data = next->value.field("Data");
    if (!id || !data) return fail("read SensorPacket", rr::make_error(rr::MessageErrorType::DataTypeMismatch, "no ID/Data field"));
    const auto* bytes = data->get_if<rr::NumericArray>();
    std::printf("packets: ID %u, %zu data bytes, sent at %lld s\n", static_cast<unsigned>(*id->as<std::uint8_t>()),
                bytes ? bytes->size() : std::size_t{0}, static_cast<long long>(next->timestamp.seconds));
    if (auto r = wire->close(); !r) return fail("close the wire", r.error());

    // The property again: the robot has moved (it drives at 200 mm/s).
    std::this_thread::sleep_for(300ms);
    auto later = root.get("DistanceTraveled");
    if (!later) return fail("get DistanceTraveled", later.error());
    std::printf("DistanceTraveled = %d mm\n", *later->as<std::int32_t>());

    if (auto r = (*client)->close_wait(); !r) return fail("close", r.error());
    std::printf("done\n");
    return 0;
}
