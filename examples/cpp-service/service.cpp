// A Robot Raconteur service in C++ with the project's server library: a service definition (robdef),
// an object with a property, a function and an event, served on a TCP port to any RR client (ours,
// the official ones, rr-gateway as a device).
//
//   rr_example_service 0            # port 0 = any free port; prints {"url": "rr+tcp://…/?service=counter"}
//   rr get 'rr+tcp://127.0.0.1:PORT/?service=counter' count
//   rr-gateway --device 'counter=rr+tcp://127.0.0.1:PORT/?service=counter'   # on the dashboard
//
// Stops on SIGINT / SIGTERM.
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>

#include "server/node/node.hpp"
#include "server/service/object_service.hpp"
#include "server/service/service_object.hpp"
#include "server/service/service_types.hpp"
#include "server/transport/tcp_listener.hpp"

using rr::Result;
using rr::Value;

namespace {

constexpr const char* kRobdef = R"(service example.counter

stdver 0.10

object Counter
    # The running total.
    property int32 count [readonly]
    # Adds n to the total (n > 0) and returns the new total.
    function int32 add(int32 n)
    # Sent after every change.
    event changed(int32 count)
end
)";

int fail(const char* step, const rr::RRError& e) {
    std::fprintf(stderr, "%s: %s: %s\n", step, e.name.c_str(), e.message.c_str());
    return 1;
}

}  // namespace

int main(int argc, char** argv) {
    const auto port = static_cast<std::uint16_t>(argc > 1 ? std::atoi(argv[1]) : 0);

    // The object type, from the robdef text (ServiceTypes checks it).
    auto types = rr::server::ServiceTypes::create({kRobdef});
    if (!types) return fail("robdef", types.error());
    auto object = rr::server::ServiceObject::create(*types, "example.counter.Counter");
    if (!object) return fail("object", object.error());
    auto counter = *object;

    // Handlers run on the node's threads, for every client: keep the state thread-safe.
    auto total = std::make_shared<std::atomic<std::int32_t>>(0);
    auto r = counter->set_property_handlers("count", [total](const rr::server::SessionRef&) -> Result<Value> {
        return Value::scalar<std::int32_t>(total->load());
    });
    if (!r) return fail("count", r.error());
    std::weak_ptr<rr::server::ServiceObject> weak = counter;
    r = counter->set_function("add", [total, weak](const rr::server::SessionRef&, std::vector<Value> args) -> Result<Value> {
        auto n = args.at(0).as<std::int32_t>();  // the argument count and types are checked before the call
        if (!n) return n.take_error();
        if (*n <= 0) return rr::fail(rr::MessageErrorType::InvalidArgument, "add: n must be positive");
        const std::int32_t now = total->fetch_add(*n) + *n;
        if (auto self = weak.lock()) (void)self->fire_event("changed", {Value::scalar<std::int32_t>(now)});
        return Value::scalar<std::int32_t>(now);
    });
    if (!r) return fail("add", r.error());

    // A node with a TCP listener, and the service on it.
    rr::server::NodeOptions options;
    options.node_name = "example.counter";
    options.threads = 2;
    auto node = rr::server::Node::create(options);
    auto bound = listen_tcp(node, "127.0.0.1", port);
    if (!bound) return fail("listen", bound.error());
    auto service = rr::server::ObjectService::create("counter", counter);
    if (!service) return fail("service", service.error());
    if (auto reg = node->register_service(*service); !reg) return fail("register", reg.error());
    std::printf("{\"url\": \"rr+tcp://127.0.0.1:%u/?service=counter\"}\n", static_cast<unsigned>(*bound));
    std::fflush(stdout);

    // Until SIGINT / SIGTERM.
    boost::asio::io_context signals_io;
    boost::asio::signal_set signals(signals_io, SIGINT, SIGTERM);
    signals.async_wait([](const boost::system::error_code&, int) {});
    signals_io.run();
    node->shutdown();
    std::printf("stopped\n");
    return 0;
}
