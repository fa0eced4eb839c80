// Callers that run the client's io_context while they wait (caller_io.hpp): a lone caller's untimed
// wait ends when its answer comes from anywhere, a second runner or a worker makes every waiter use
// slices, and a real client with caller_runs_io completes calls from several threads and times out
// unanswered ones.
#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <future>
#include <thread>
#include <vector>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "server/client/client.hpp"
#include "server/node/node.hpp"
#include "server/node/test_node.hpp"
#include "server/service/test_raw_service.hpp"
#include "server/transport/tcp_listener.hpp"

using namespace rr;
using namespace std::chrono_literals;

// Named, not anonymous: in the unity build (preset tsan) other test files' helpers share the batch.
namespace caller_io_test {

using rr::client::detail::SyncWaiter;
using Clock = std::chrono::steady_clock;

// A thread waiting for `waiter`'s answer with run_io_until on `io`, untimed when alone; ended() tells whether it
// returned within `limit`. A waiter left asleep is woken by the test itself (so a failure does not
// hang the run) and reported.
struct UntimedWaiter {
    boost::asio::io_context& io;
    std::shared_ptr<SyncWaiter<int>> waiter = std::make_shared<SyncWaiter<int>>();
    std::promise<bool> done;
    std::future<bool> result = done.get_future();
    std::thread thread;

    explicit UntimedWaiter(boost::asio::io_context& context) : io(context) {
        // The waiter is made on the waiting thread (its UntimedWait records that thread).
        std::promise<void> made;
        auto ready = made.get_future();
        thread = std::thread([this, &made] {
            waiter = std::make_shared<SyncWaiter<int>>();
            made.set_value();
            done.set_value(rr::client::detail::run_io_until(
                io, [w = waiter] { return w->answered(); }, Clock::now() + 60s, &waiter->untimed_wait));
        });
        ready.wait();
    }
    bool ended(std::chrono::milliseconds limit) {
        const bool in_time = result.wait_for(limit) == std::future_status::ready;
        while (result.wait_for(1ms) != std::future_status::ready) boost::asio::post(io, [] {});  // unstick it
        thread.join();
        return in_time && result.get();
    }
};

int runners_of(boost::asio::io_context& io) { return rr::client::detail::caller_io_runners(io).runners.load(); }

template <class Pred>
bool eventually(Pred pred, std::chrono::milliseconds limit = 30s) {  // a bound on a hang
    const auto until = Clock::now() + limit;
    while (!pred()) {
        if (Clock::now() > until) return false;
        std::this_thread::sleep_for(1ms);
    }
    return true;
}

}  // namespace caller_io_test

namespace cit = caller_io_test;

TEST_CASE("caller io: a lone caller's untimed wait ends when a thread that does not run the io_context answers") {
    boost::asio::io_context io;
    auto guard = boost::asio::make_work_guard(io);
    for (int i = 0; i < 50; ++i) {
        cit::UntimedWaiter a(io);
        REQUIRE(cit::eventually([&] { return cit::runners_of(io) == 1; }));
        std::this_thread::sleep_for(std::chrono::microseconds(200 * (i % 5)));  // asleep, or about to be
        a.waiter->set(5);  // this thread never runs `io`: the set must wake the waiter
        INFO("iteration " << i);
        REQUIRE(a.ended(30s));  // a lost wake-up waits for the 60 s deadline
    }
    CHECK(cit::runners_of(io) == 0);
}

TEST_CASE("caller io: a second thread running the io_context wakes the untimed waiter, whoever runs its answer") {
    boost::asio::io_context io;
    auto guard = boost::asio::make_work_guard(io);
    for (int i = 0; i < 100; ++i) {
        cit::UntimedWaiter a(io);
        REQUIRE(cit::eventually([&] { return cit::runners_of(io) == 1; }));
        std::atomic<bool> b_done{false};
        std::thread b([&] {
            rr::client::detail::run_io_until(io, [&] { return b_done.load(); }, cit::Clock::now() + 60s);
        });
        REQUIRE(cit::eventually([&] { return cit::runners_of(io) == 2; }));
        // The answer is a handler: either thread may run it. If `a` were still asleep without a
        // timeout while `b` ran it, nothing would wake `a`.
        boost::asio::post(io, [w = a.waiter] { w->set(7); });
        INFO("iteration " << i);
        REQUIRE(a.ended(30s));  // a lost wake-up waits for the 60 s deadline
        b_done = true;
        boost::asio::post(io, [] {});
        b.join();
    }
    CHECK(cit::runners_of(io) == 0);
}

TEST_CASE("caller io: while worker threads run the io_context nobody waits untimed") {
    rr::client::IoThreads workers(1);
    auto* io = &boost::asio::query(workers.executor(), boost::asio::execution::context);
    auto& context = static_cast<boost::asio::io_context&>(*io);
    CHECK(rr::client::detail::caller_io_runners(context).workers.load() == 1);
    for (int i = 0; i < 100; ++i) {
        cit::UntimedWaiter a(context);
        REQUIRE(cit::eventually([&] { return cit::runners_of(context) == 1; }));
        boost::asio::post(context, [w = a.waiter] { w->set(1); });  // the worker may run it
        INFO("iteration " << i);
        REQUIRE(a.ended(30s));  // a lost wake-up waits for the 60 s deadline
    }
}

namespace caller_io_test {

// RawTestService whose `add` is never answered (its responders are kept until the service goes).
class SilentAddService : public server::testing::RawTestService {
public:
    void handle_entry(const server::SessionRef& session, MessageEntry&& e, server::Responder responder) override {
        if (e.entry_type == MessageEntryType::FunctionCallReq && e.member_name == "add") {
            std::lock_guard lock(held_mutex);
            held.push_back(std::move(responder));
            return;
        }
        RawTestService::handle_entry(session, std::move(e), std::move(responder));
    }
    std::mutex held_mutex;
    std::vector<server::Responder> held;
};

struct CallerIoFixture {
    std::shared_ptr<server::Node> node = server::testing::test_node("calleriotest.node");
    std::shared_ptr<SilentAddService> service = std::make_shared<SilentAddService>();
    std::uint16_t port = 0;
    rr::client::IoThreads none{0};

    CallerIoFixture() {
        REQUIRE(node->register_service(service));
        auto p = listen_tcp(node, "127.0.0.1", 0);
        REQUIRE(p);
        port = *p;
    }
    ~CallerIoFixture() { node->shutdown(); }

    std::shared_ptr<rr::client::Client> connect(std::chrono::milliseconds request_timeout = 15s) {
        rr::client::ClientOptions o;
        o.caller_runs_io = true;
        o.request_timeout = request_timeout;
        auto c = rr::client::Client::connect(none.executor(), "rr+tcp://127.0.0.1:" + std::to_string(port) + "/?service=svc", o);
        INFO((c ? std::string() : c.error().message));
        REQUIRE(c);
        return *c;
    }
};

}  // namespace caller_io_test

TEST_CASE("caller io: a client with caller_runs_io answers calls from one and from three threads") {
    cit::CallerIoFixture f;
    auto c = f.connect();
    auto root = c->root();
    for (int i = 0; i < 500; ++i) {
        auto x = root.get("x");
        REQUIRE(x);
        REQUIRE(*x == Value::scalar(42.5));
    }
    // The service's callme calls the client's callback cb, which runs on whichever caller runs the I/O.
    REQUIRE(root.set_callback("cb", [](std::vector<Value>& a) -> Result<Value> { return Value::scalar(*a.at(0).as<double>() + 0.5); }));
    // Three threads at once: each waits alone at times and with the others at times.
    std::atomic<int> wrong{0}, done{0};
    std::vector<std::thread> threads;
    for (int t = 0; t < 3; ++t)
        threads.emplace_back([&, t] {
            for (int i = 0; i < 300; ++i) {
                auto r = root.call("callme", {Value::scalar(double(t * 1000 + i))});  // a callback round trip too
                if (!r || !(*r == Value::scalar(double(t * 1000 + i) + 0.5))) ++wrong;
                if (i % 50 == 0) std::this_thread::sleep_for(1ms);
            }
            ++done;
        });
    for (auto& t : threads) t.join();
    CHECK(done == 3);
    CHECK(wrong == 0);
    CHECK(cit::runners_of(static_cast<boost::asio::io_context&>(boost::asio::query(f.none.executor(), boost::asio::execution::context))) == 0);
}

// [timing]: it asserts how long the call took.
TEST_CASE("caller io: an unanswered call ends with the request timeout, not later", "[timing]") {
    cit::CallerIoFixture f;
    auto c = f.connect(300ms);
    auto root = c->root();
    const auto t0 = cit::Clock::now();
    auto r = root.call("add", {Value::scalar<std::int32_t>(1), Value::scalar<std::int32_t>(2)});
    const auto took = cit::Clock::now() - t0;
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::RequestTimeout);
    CHECK(took >= 250ms);
    CHECK(took < 3s);
    // The connection is still usable.
    auto x = root.get("x");
    REQUIRE(x);
    CHECK(*x == Value::scalar(42.5));
}
