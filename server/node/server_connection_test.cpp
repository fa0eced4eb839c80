// Node + ServerConnection + RawClient over real loopback TCP, with a hand-written entry-level service.
#include <catch2/catch.hpp>

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <future>
#include <mutex>
#include <thread>

#include <boost/asio/connect.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/write.hpp>

#include "core/session/elements.hpp"
#include "server/client/raw_client.hpp"
#include "server/node/node.hpp"
#include "server/node/server_connection.hpp"
#include "server/service/test_raw_service.hpp"
#include "server/transport/tcp_listener.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace rr::server;
using namespace std::chrono_literals;

namespace {

using rr::server::testing::RawTestService;
using rr::server::testing::kDef;

struct Fixture {
    std::shared_ptr<Node> node = Node::create(NodeOptions{NodeID(), "rawtest.node", 2, {}, 0, 5000ms});
    std::shared_ptr<RawTestService> service;
    std::uint16_t port = 0;

    explicit Fixture(std::shared_ptr<RawTestService> s = std::make_shared<RawTestService>()) : service(std::move(s)) {
        REQUIRE(node->register_service(service));
        auto p = listen_tcp(node, "127.0.0.1", 0);
        REQUIRE(p);
        port = *p;
    }

    std::shared_ptr<RawClient> connect(RawClient::IncomingHandler incoming = {}, RawClientOptions opts = {}) {
        std::promise<Result<std::shared_ptr<RawClient>>> p;
        auto url = parse_connection_url("rr+tcp://127.0.0.1:" + std::to_string(port) + "/?service=svc");
        REQUIRE(url);
        RawClient::connect(node->io_context().get_executor(), *url, opts, std::move(incoming), {},
                           [&](Result<std::shared_ptr<RawClient>> r) { p.set_value(std::move(r)); });
        auto r = p.get_future().get();
        REQUIRE(r);
        return *r;
    }

    static Result<MessageEntry> call(RawClient& c, MessageEntry e) {
        std::promise<Result<MessageEntry>> p;
        c.request(std::move(e), [&](Result<MessageEntry> r) { p.set_value(std::move(r)); });
        return p.get_future().get();
    }
};

MessageEntry request(MessageEntryType type, std::string member) {
    MessageEntry e;
    e.entry_type = type;
    e.service_path = "svc";
    e.member_name = std::move(member);
    return e;
}

}  // namespace

TEST_CASE("client connects with ConnectClientCombined and gets the service definition") {
    for (bool v4 : {true, false}) {
        Fixture f;
        RawClientOptions opts;
        opts.enable_message4 = v4;
        auto c = f.connect({}, opts);
        CHECK(c->info().object_type == "example.rawtest.Obj");
        REQUIRE(c->info().service_definitions.size() == 1);
        CHECK(c->info().service_definitions[0] == kDef);
        CHECK(c->remote_node_name() == "rawtest.node");
        CHECK(c->remote_node_id() == f.node->node_id());

        auto get = Fixture::call(*c, request(MessageEntryType::PropertyGetReq, "x"));
        REQUIRE(get);
        double x = 0;
        REQUIRE(get->find("value"));
        CHECK(read_scalar(*get->find("value"), x));
        CHECK(x == 42.5);

        auto add = request(MessageEntryType::FunctionCallReq, "add");
        add.elements.push_back(make_scalar_element<std::int32_t>("a", 40));
        add.elements.push_back(make_scalar_element<std::int32_t>("b", 2));
        auto sum = Fixture::call(*c, std::move(add));
        REQUIRE(sum);
        std::int32_t s = 0;
        CHECK(read_scalar(*sum->find("return"), s));
        CHECK(s == 42);
    }
}

TEST_CASE("errors from a service arrive as RR error entries and the session stays up") {
    Fixture f;
    auto c = f.connect();
    auto bad = Fixture::call(*c, request(MessageEntryType::FunctionCallReq, "nosuch"));
    REQUIRE(bad);
    CHECK(bad->error == MessageErrorType::MemberNotFound);
    auto err = *entry_error(*bad);
    CHECK(err.name == "RobotRaconteur.MemberNotFound");
    CHECK(err.message == "Member \"nosuch\" not found");
    auto ok = Fixture::call(*c, request(MessageEntryType::PropertyGetReq, "x"));
    REQUIRE(ok);
    CHECK(ok->error == MessageErrorType::None);
}

TEST_CASE("events reach the client and callbacks reach back into it") {
    Fixture f;
    std::promise<MessageEntry> event;
    std::weak_ptr<RawClient> weak;
    bool event_set = false;
    auto c = f.connect([&](MessageEntry&& e) {
        if (e.entry_type == MessageEntryType::EventReq && !event_set) {
            event_set = true;
            event.set_value(std::move(e));
        } else if (e.entry_type == MessageEntryType::CallbackCallReq) {
            double v = 0;
            read_scalar(*e.find("v"), v);
            MessageEntry r;
            r.entry_type = MessageEntryType::CallbackCallRet;
            r.service_path = e.service_path;
            r.member_name = e.member_name;
            r.request_id = e.request_id;
            r.elements.push_back(make_scalar_element("return", v * 2));
            if (auto cl = weak.lock()) cl->send(std::move(r));
        }
    });
    weak = c;
    REQUIRE(Fixture::call(*c, request(MessageEntryType::FunctionCallReq, "fire")));
    auto ev = event.get_future();
    REQUIRE(ev.wait_for(30s) == std::future_status::ready);
    auto e = ev.get();
    CHECK(e.member_name == "changed");
    double v = 0;
    CHECK(read_scalar(*e.find("v"), v));
    CHECK(v == 7.0);

    auto callme = request(MessageEntryType::FunctionCallReq, "callme");
    callme.elements.push_back(make_scalar_element("v", 21.0));
    auto r = Fixture::call(*c, std::move(callme));
    REQUIRE(r);
    double ret = 0;
    REQUIRE(r->find("return"));
    CHECK(read_scalar(*r->find("return"), ret));
    CHECK(ret == 42.0);
}

TEST_CASE("connecting to an unknown service fails with ServiceNotFound") {
    Fixture f;
    std::promise<Result<std::shared_ptr<RawClient>>> p;
    auto url = parse_connection_url("rr+tcp://127.0.0.1:" + std::to_string(f.port) + "/?service=nosuch");
    RawClient::connect(f.node->io_context().get_executor(), *url, {}, {}, {},
                       [&](Result<std::shared_ptr<RawClient>> r) { p.set_value(std::move(r)); });
    auto r = p.get_future().get();
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::ServiceNotFound);
    // The client reports it under the standard name with the service named (the wire keeps CORE's
    // name "RobotRaconteur.ServiceNotFoundException": test/cli/service_index_official.py checks the
    // official client's view).
    CHECK(r.error().name == "RobotRaconteur.ServiceNotFound");
    CHECK_THAT(r.error().message, Catch::Contains("\"nosuch\""));
}

namespace {

// Writes raw bytes on a fresh socket and reads until the server closes (or 30 s pass: a bound on a hang).
std::string raw_exchange(std::uint16_t port, const std::string& bytes) {
    boost::asio::io_context io;
    boost::asio::ip::tcp::socket s(io);
    s.connect({boost::asio::ip::make_address("127.0.0.1"), port});
    boost::asio::write(s, boost::asio::buffer(bytes));
    std::string got;
    std::array<char, 4096> buf;
    boost::system::error_code ec;
    auto deadline = std::chrono::steady_clock::now() + 30s;
    s.non_blocking(true);
    while (std::chrono::steady_clock::now() < deadline) {
        auto n = s.read_some(boost::asio::buffer(buf), ec);
        if (ec == boost::asio::error::would_block) {
            std::this_thread::sleep_for(10ms);
            continue;
        }
        if (ec) break;
        got.append(buf.data(), n);
    }
    if (!ec || ec == boost::asio::error::would_block) got += "<still open>";
    return got;
}

}  // namespace

TEST_CASE("misbehaving peers are answered or dropped while other clients keep working") {
    Fixture f;
    auto good = f.connect();

    // Not RR, not the start of an HTTP request: dropped without an answer.
    CHECK(raw_exchange(f.port, "XXXXhello").empty());
    // RRAC with a 4 GiB MessageSize: closed without allocating.
    std::string huge = "RRAC";
    huge += std::string("\xff\xff\xff\xff", 4);
    CHECK(raw_exchange(f.port, huge).empty());
    // A message before CreateConnection / truncated garbage after a valid preamble: closed.
    std::string trunc = "RRAC";
    trunc += std::string("\x40\x00\x00\x00", 4);
    trunc += std::string(56, '\x01');
    CHECK(raw_exchange(f.port, trunc).find("<still open>") == std::string::npos);

    auto ok = Fixture::call(*good, request(MessageEntryType::PropertyGetReq, "x"));
    REQUIRE(ok);
    CHECK(ok->error == MessageErrorType::None);
}

TEST_CASE("disconnect closes the session on the service") {
    Fixture f;
    {
        auto c = f.connect();
        CHECK(f.service->opened == 1);
        c->close();
    }
    CHECK(rr::testing::eventually([&] { return f.service->closed != 0; }));
    CHECK(f.service->closed == 1);
}

TEST_CASE("a client that sends requests but never reads replies is throttled, others are unaffected") {
    Fixture f;
    auto good = f.connect();

    // A misbehaving client: connects properly, then floods property gets and never reads.
    boost::asio::io_context io;
    boost::asio::ip::tcp::socket s(io);
    s.connect({boost::asio::ip::make_address("127.0.0.1"), f.port});
    ClientSessionConfig cfg;
    cfg.stream.local_node_id = *NodeID::parse("99999999-2222-3333-4444-555555555555");
    cfg.service_name = "svc";
    cfg.local_endpoint = 7;
    auto now = std::chrono::steady_clock::now();
    ClientSession session(cfg, now);
    std::array<std::byte, 65536> buf;
    for (int i = 0; i < 50 && !session.is_connected(); ++i) {
        auto out = session.pending_output();
        boost::asio::write(s, boost::asio::buffer(out.data(), out.size()));
        session.consume_output(out.size());
        auto n = s.read_some(boost::asio::buffer(buf));
        REQUIRE(session.feed(std::span<const std::byte>(buf.data(), n), now));
    }
    REQUIRE(session.is_connected());

    s.non_blocking(true);
    std::size_t written = 0;
    auto last_progress = std::chrono::steady_clock::now();
    const auto give_up = last_progress + 30s;
    std::vector<std::byte> pending;
    MessageEntry get;
    get.entry_type = MessageEntryType::PropertyGetReq;
    get.service_path = "svc";
    get.member_name = "x";
    while (std::chrono::steady_clock::now() < give_up && written < (256u << 20)) {
        if (pending.empty()) {
            for (int k = 0; k < 1000; ++k) REQUIRE(session.request(MessageEntry(get), now));
            auto out = session.pending_output();
            pending.assign(out.begin(), out.end());
            session.consume_output(out.size());
        }
        boost::system::error_code ec;
        auto n = s.write_some(boost::asio::buffer(pending.data(), pending.size()), ec);
        if (ec == boost::asio::error::would_block) {
            if (std::chrono::steady_clock::now() - last_progress > 1500ms) break;  // the server stopped reading
            std::this_thread::sleep_for(5ms);
            continue;
        }
        REQUIRE_FALSE(ec);
        written += n;
        pending.erase(pending.begin(), pending.begin() + static_cast<std::ptrdiff_t>(n));
        last_progress = std::chrono::steady_clock::now();
    }
    INFO("bytes the server accepted from the flooding client: " << written);
    CHECK(written < (64u << 20));

    // Meanwhile a well-behaved client is served normally.
    auto ok = Fixture::call(*good, request(MessageEntryType::PropertyGetReq, "x"));
    REQUIRE(ok);
    CHECK(ok->error == MessageErrorType::None);
}

namespace {

// RawTestService whose `add` with an even `a` is answered by a thread of its own (a service completing
// replies off the connection's strand, like a device answering for a gateway); an odd `a` is answered
// inside handle_entry, on the connection's own handler. While held, deferred requests wait.
class ForeignThreadReplyService : public RawTestService {
public:
    ForeignThreadReplyService() : worker_([this] { run(); }) {}
    ~ForeignThreadReplyService() override { stop(); }

    void handle_entry(const SessionRef& session, MessageEntry&& e, Responder responder) override {
        std::int32_t a = 0, b = 0;
        const auto* ea = e.find("a");
        const auto* eb = e.find("b");
        if (e.entry_type == MessageEntryType::FunctionCallReq && e.member_name == "add" && ea && eb &&
            read_scalar(*ea, a) && read_scalar(*eb, b) && a % 2 == 0) {
            std::lock_guard lock(queue_mutex_);
            queue_.emplace_back(std::move(responder), a + b);
            queued_.fetch_add(1);
            wake_.notify_all();
            return;
        }
        RawTestService::handle_entry(session, std::move(e), std::move(responder));
    }

    void hold(bool on) {
        std::lock_guard lock(queue_mutex_);
        held_ = on;
        wake_.notify_all();
    }
    void stop() {
        {
            std::lock_guard lock(queue_mutex_);
            if (stopping_) return;
            stopping_ = true;
            held_ = false;
            wake_.notify_all();
        }
        worker_.join();
    }

    std::atomic<int> queued_{0}, answered_{0};

private:
    void run() {
        std::unique_lock lock(queue_mutex_);
        for (;;) {
            wake_.wait(lock, [&] { return stopping_ || (!held_ && !queue_.empty()); });
            if (queue_.empty() && stopping_) return;
            auto [responder, sum] = std::move(queue_.front());
            queue_.pop_front();
            lock.unlock();
            MessageEntry r;
            r.elements.push_back(make_scalar_element<std::int32_t>("return", sum));
            responder.respond(std::move(r));
            answered_.fetch_add(1);
            lock.lock();
        }
    }

    std::mutex queue_mutex_;
    std::condition_variable wake_;
    std::deque<std::pair<Responder, std::int32_t>> queue_;
    bool held_ = false, stopping_ = false;
    std::thread worker_;  // last: started once the members above exist
};

MessageEntry add_call(std::int32_t a, std::int32_t b) {
    MessageEntry e = request(MessageEntryType::FunctionCallReq, "add");
    e.elements.push_back(make_scalar_element<std::int32_t>("a", a));
    e.elements.push_back(make_scalar_element<std::int32_t>("b", b));
    return e;
}

}  // namespace

TEST_CASE("replies completed on another thread and on the connection's own handler reach their own requests") {
    auto service = std::make_shared<ForeignThreadReplyService>();
    Fixture f(service);
    constexpr int kClients = 2, kCalls = 200;
    struct Tally {
        std::atomic<int> done{0}, wrong{0};
        std::promise<void> all;
    };
    auto tally = std::make_shared<Tally>();
    std::vector<std::shared_ptr<RawClient>> clients;
    for (int c = 0; c < kClients; ++c) clients.push_back(f.connect());
    // Both kinds in flight at once on each connection, from both clients: each reply carries its own
    // request's sum, so a reply queued for the wrong request or connection shows.
    for (int i = 0; i < kCalls; ++i) {
        for (int c = 0; c < kClients; ++c) {
            const std::int32_t a = i, b = 1000 * (c + 1);
            clients[c]->request(add_call(a, b), [tally, a, b](Result<MessageEntry> r) {
                std::int32_t got = -1;
                const bool ok = r && r->error == MessageErrorType::None && r->find("return") &&
                                read_scalar(*r->find("return"), got) && got == a + b;
                if (!ok) tally->wrong.fetch_add(1);
                if (tally->done.fetch_add(1) + 1 == kClients * kCalls) tally->all.set_value();
            });
        }
    }
    REQUIRE(tally->all.get_future().wait_for(30s) == std::future_status::ready);
    CHECK(tally->wrong == 0);
    CHECK(service->answered_ == kClients * kCalls / 2);
}

TEST_CASE("replies completed on another thread after the client has gone are dropped, the node keeps serving") {
    auto service = std::make_shared<ForeignThreadReplyService>();
    Fixture f(service);
    service->hold(true);
    {
        auto c = f.connect();
        for (int i = 0; i < 20; ++i) c->request(add_call(2 * i, 1), [](Result<MessageEntry>) {});
        REQUIRE(rr::testing::eventually([&] { return service->queued_ >= 20; }));
        REQUIRE(service->queued_ == 20);
        c->close();
    }
    REQUIRE(rr::testing::eventually([&] { return service->closed != 0; }));
    REQUIRE(service->closed == 1);
    service->hold(false);  // the 20 Responders now complete with their connection and pump gone
    CHECK(rr::testing::eventually([&] { return service->answered_ >= 20; }));
    CHECK(service->answered_ == 20);

    auto c = f.connect();
    auto r = Fixture::call(*c, add_call(4, 5));
    REQUIRE(r);
    std::int32_t sum = 0;
    REQUIRE(r->find("return"));
    CHECK(read_scalar(*r->find("return"), sum));
    CHECK(sum == 9);
}

namespace {
// Answers `add` on its own thread, with an event `changed` (v = the sum) sent just before the reply
// when `a` is even and just after it when odd: the order a client must see them in.
class EventAndReplyService final : public RawTestService {
public:
    EventAndReplyService() : worker_([this] { run(); }) {}
    ~EventAndReplyService() override {
        {
            std::lock_guard lock(mutex_);
            stopping_ = true;
            wake_.notify_all();
        }
        worker_.join();
    }

    void handle_entry(const SessionRef& session, MessageEntry&& e, Responder responder) override {
        std::int32_t a = 0, b = 0;
        const auto* ea = e.find("a");
        const auto* eb = e.find("b");
        if (e.entry_type != MessageEntryType::FunctionCallReq || e.member_name != "add" || !ea || !eb ||
            !read_scalar(*ea, a) || !read_scalar(*eb, b))
            return RawTestService::handle_entry(session, std::move(e), std::move(responder));
        std::lock_guard lock(mutex_);
        work_.push_back(Work{session, std::move(responder), a, b});
        wake_.notify_all();
    }

private:
    struct Work {
        SessionRef session;
        Responder responder;
        std::int32_t a, b;
    };
    void run() {
        std::unique_lock lock(mutex_);
        for (;;) {
            wake_.wait(lock, [&] { return stopping_ || !work_.empty(); });
            if (work_.empty()) return;
            auto w = std::move(work_.front());
            work_.pop_front();
            lock.unlock();
            MessageEntry ev;
            ev.entry_type = MessageEntryType::EventReq;
            ev.service_path = "svc";
            ev.member_name = "changed";
            ev.elements.push_back(make_scalar_element("v", double(w.a + w.b)));
            MessageEntry r;
            r.elements.push_back(make_scalar_element<std::int32_t>("return", w.a + w.b));
            if (w.a % 2 == 0) {
                (void)w.session.send(std::move(ev));
                w.responder.respond(std::move(r));
            } else {
                w.responder.respond(std::move(r));
                (void)w.session.send(std::move(ev));
            }
            lock.lock();
        }
    }

    std::mutex mutex_;
    std::condition_variable wake_;
    std::deque<Work> work_;
    bool stopping_ = false;
    std::thread worker_;  // last: started once the members above exist
};
}  // namespace

TEST_CASE("a worker thread's event and reply reach the client in the order it sent them") {
    auto service = std::make_shared<EventAndReplyService>();
    Fixture f(service);
    constexpr int kCalls = 300;
    struct Seen {
        std::mutex mutex;
        std::vector<std::pair<char, std::int32_t>> order;  // ('e', v) event, ('r', sum) reply
        std::promise<void> all;
        int replies = 0;
    };
    auto seen = std::make_shared<Seen>();
    auto c = f.connect([seen](MessageEntry&& e) {
        double v = -1;
        if (e.entry_type == MessageEntryType::EventReq && e.find("v")) (void)read_scalar(*e.find("v"), v);
        std::lock_guard lock(seen->mutex);
        seen->order.emplace_back('e', static_cast<std::int32_t>(v));
    });
    for (int i = 0; i < kCalls; ++i) {
        c->request(add_call(i, 1000 * i), [seen](Result<MessageEntry> r) {
            std::int32_t sum = -1;
            if (r && r->find("return")) (void)read_scalar(*r->find("return"), sum);
            std::lock_guard lock(seen->mutex);
            seen->order.emplace_back('r', sum);
            if (++seen->replies == kCalls) seen->all.set_value();
        });
    }
    REQUIRE(seen->all.get_future().wait_for(30s) == std::future_status::ready);
    // The last call's event may follow its reply: wait for it.
    rr::testing::eventually([&] {
        std::lock_guard lock(seen->mutex);
        return seen->order.size() >= 2u * kCalls;
    });
    std::lock_guard lock(seen->mutex);
    REQUIRE(seen->order.size() == 2u * kCalls);
    int wrong = 0;
    for (int i = 0; i < kCalls; ++i) {
        const std::int32_t sum = i + 1000 * i;
        const auto e = std::find(seen->order.begin(), seen->order.end(), std::make_pair('e', sum));
        const auto r = std::find(seen->order.begin(), seen->order.end(), std::make_pair('r', sum));
        if (e == seen->order.end() || r == seen->order.end() || (i % 2 == 0) != (e < r)) ++wrong;
    }
    CHECK(wrong == 0);
}

TEST_CASE("a request made while the client connection closes is answered once, never lost") {
    Fixture f;
    int local_errors = 0;
    for (int i = 0; i < 40; ++i) {
        auto c = f.connect();
        std::promise<Result<MessageEntry>> answered;
        auto answer = answered.get_future();
        c->close();  // queued on the connection's strand before the request
        c->request(request(MessageEntryType::PropertyGetReq, "x"),
                   [&answered](Result<MessageEntry> r) { answered.set_value(std::move(r)); });  // twice would throw
        REQUIRE(answer.wait_for(30s) == std::future_status::ready);
        auto r = answer.get();
        if (!r) {
            ++local_errors;
            CHECK((r.error().type == MessageErrorType::ConnectionError || r.error().type == MessageErrorType::InvalidState));
        }
    }
    CHECK(local_errors > 0);  // the close won the race at least once
}

TEST_CASE("requests racing the end of the client's transport are each answered once, never lost") {
    Fixture f;
    // The client on an io_context of its own, so that the service's node can shut down under it.
    boost::asio::io_context client_io;
    auto work = boost::asio::make_work_guard(client_io);
    std::vector<std::thread> io_threads;
    for (int i = 0; i < 2; ++i) io_threads.emplace_back([&] { client_io.run(); });
    std::shared_ptr<RawClient> c;
    {
        std::promise<Result<std::shared_ptr<RawClient>>> p;
        auto url = parse_connection_url("rr+tcp://127.0.0.1:" + std::to_string(f.port) + "/?service=svc");
        REQUIRE(url);
        RawClient::connect(client_io.get_executor(), *url, {}, {}, {},
                           [&](Result<std::shared_ptr<RawClient>> r) { p.set_value(std::move(r)); });
        auto r = p.get_future().get();
        REQUIRE(r);
        c = *r;
    }
    // The sender keeps requesting until the client has seen its transport end, then a few more: the
    // requests meet a live service, the shutdown in progress, and the ended transport.
    constexpr int kMaxRequests = 200000;
    struct Tally {
        std::vector<std::atomic<int>> calls = std::vector<std::atomic<int>>(kMaxRequests);
        std::atomic<int> answered{0}, replies{0}, errors{0};
    };
    auto tally = std::make_shared<Tally>();
    std::atomic<int> sent{0};
    std::thread sender([&] {
        int after_end = 0;
        for (int i = 0; i < kMaxRequests && after_end < 20; ++i) {
            if (!c->is_open()) ++after_end;
            c->request(add_call(i, 1), [tally, i](Result<MessageEntry> r) {
                tally->calls[i].fetch_add(1);
                (r ? tally->replies : tally->errors).fetch_add(1);
                tally->answered.fetch_add(1);
            });
            sent.store(i + 1);
            if (i % 64 == 63) std::this_thread::sleep_for(100us);  // a flood, not an unbounded queue
            // At most 4096 unanswered while the transport lasts: a shutdown slowed by a loaded machine
            // must not let the sender run through every request before the end is seen.
            while (c->is_open() && i + 1 - tally->answered.load() > 4096) std::this_thread::sleep_for(100us);
        }
    });
    // The device goes away while the requests are being made.
    while (tally->answered.load() < 50) std::this_thread::sleep_for(1ms);
    f.node->shutdown();
    sender.join();
    const int requests = sent.load();
    REQUIRE(requests < kMaxRequests);  // the client saw its transport end
    CHECK(rr::testing::eventually([&] { return tally->answered.load() >= requests; }));
    CHECK(tally->answered.load() == requests);
    int wrong = 0;
    for (int i = 0; i < requests; ++i) wrong += tally->calls[i].load() != 1;
    CHECK(wrong == 0);
    CHECK(tally->replies.load() >= 50);
    CHECK(tally->errors.load() >= 20);  // at least those made after the end
    // Once the transport has ended, a request is answered ConnectionError at once.
    CHECK_FALSE(c->is_open());
    bool called = false;
    c->request(add_call(1, 2), [&](Result<MessageEntry> r) {
        called = true;
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::ConnectionError);
    });
    CHECK(called);
    c.reset();
    work.reset();
    client_io.stop();
    for (auto& t : io_threads) t.join();
}

namespace {
// A pump that has closed: work posted to it is destroyed unrun (as StreamPump does after close).
class ClosedPump final : public PumpHandle {
public:
    void post(std::function<void()> fn) override { ++dropped; }
    void dispatch(std::function<void()> fn) override { ++dropped; }
    void wake() override { ++dropped; }
    void close() override {}
    int dropped = 0;
};
}  // namespace

TEST_CASE("a callback request whose work a closed pump drops is answered ConnectionError, once") {
    auto pump = std::make_shared<ClosedPump>();
    auto session = std::make_shared<ServerSession>(1, 2, nullptr, pump, std::weak_ptr<ServerConnection>(), 1u << 20);
    int calls = 0;
    Result<MessageEntry> got = MessageEntry{};
    SessionRef(session).request(request(MessageEntryType::CallbackCallReq, "cb"), [&](Result<MessageEntry> r) {
        ++calls;
        got = std::move(r);
    });
    CHECK(pump->dropped == 1);
    CHECK(calls == 1);
    REQUIRE(!got);
    CHECK(got.error().type == MessageErrorType::ConnectionError);
    CHECK(got.error().message == "client session closed");
}

namespace {
// A pump that keeps what is handed to it, unrun: the test plays the strand.
class KeepingPump final : public PumpHandle {
public:
    void post(std::function<void()> fn) override { held.push_back(std::move(fn)); }
    void dispatch(std::function<void()> fn) override { held.push_back(std::move(fn)); }
    void wake() override { ++wakes; }
    bool known_off_strand() const override { return off_strand; }
    void close() override {}
    std::vector<std::function<void()>> held;
    int wakes = 0;
    bool off_strand = false;
};

MessageEntry wire_packet_with(const std::string& member, std::int32_t v) {
    MessageEntry e = request(MessageEntryType::WirePacket, member);
    e.elements.push_back(make_scalar_element<std::int32_t>("value", v));
    return e;
}

std::int32_t value_of(const MessageEntry& e) {
    std::int32_t v = -1;
    if (const auto* el = e.find("value")) (void)read_scalar(*el, v);
    return v;
}

// What a queued send is, and its value: "shared", "own" or "reply".
std::pair<std::string, std::int32_t> pending_send(const ServerSession::PendingSend& p) {
    if (const auto* shared = std::get_if<std::shared_ptr<const EncodedEntry>>(&p)) return {"shared", value_of((*shared)->entry())};
    if (const auto* own = std::get_if<MessageEntry>(&p)) return {"own", value_of(*own)};
    return {"reply", value_of(std::get<ServerSession::PendingReply>(p).entry)};
}

std::int32_t pending_value(const ServerSession::PendingSend& p) { return pending_send(p).second; }

std::int32_t pending_value(const ServerSession::PendingWire& p) {
    const MessageEntry& e = std::holds_alternative<MessageEntry>(p) ? std::get<MessageEntry>(p)
                                                                     : std::get<std::shared_ptr<const EncodedEntry>>(p)->entry();
    std::int32_t v = -1;
    if (const auto* el = e.find("value")) (void)read_scalar(*el, v);
    return v;
}
}  // namespace

TEST_CASE("pending wire packets: one wake per session until taken, the newest per member, own or shared") {
    auto pump = std::make_shared<KeepingPump>();
    auto session = std::make_shared<ServerSession>(1, 2, nullptr, pump, std::weak_ptr<ServerConnection>(), 1u << 20);
    const SessionRef ref(session);
    std::vector<ServerSession::PendingWire> taken;
    std::vector<ServerSession::PendingSend> sends;
    const auto values = [&] {
        std::vector<std::int32_t> v;
        for (const auto& p : taken) v.push_back(pending_value(p));
        taken.clear();
        return v;
    };

    REQUIRE(ref.send_wire_packet(wire_packet_with("w", 1)));
    REQUIRE(ref.send_wire_packet(std::make_shared<const EncodedEntry>(wire_packet_with("w", 2))));
    REQUIRE(ref.send_wire_packet(wire_packet_with("x", 7)));
    CHECK(pump->wakes == 1);  // the later packets ride on the first wake
    CHECK(pump->held.empty());
    session->take_queued(sends, taken);
    CHECK(values() == std::vector<std::int32_t>{2, 7});  // "w" replaced by its newest value, key order
    session->take_queued(sends, taken);
    CHECK(taken.empty());

    // After a take, the next packet wakes again; members do not replace each other, also beyond the
    // slots a session keeps between values.
    REQUIRE(ref.send_wire_packet(wire_packet_with("w", 3)));
    CHECK(pump->wakes == 2);
    int wakes = 2;
    for (int round = 0; round < 3; ++round) {
        for (int m = 0; m < 80; ++m) REQUIRE(ref.send_wire_packet(wire_packet_with("m" + std::to_string(m), m + 100 * round)));
        if (round > 0) ++wakes;  // in round 0 the packets ride on the wake for "w"
        CHECK(pump->wakes == wakes);
        session->take_queued(sends, taken);
        auto got = values();
        REQUIRE(got.size() == (round == 0 ? 81u : 80u));
        if (round == 0) {
            CHECK(got.back() == 3);  // "w", last in key order
            got.pop_back();
        }
        std::sort(got.begin(), got.end());
        for (int m = 0; m < 80; ++m) CHECK(got[m] == m + 100 * round);
        REQUIRE(ref.send_wire_packet(wire_packet_with("w", 4)));
        CHECK(pump->wakes == ++wakes);
        session->take_queued(sends, taken);
        CHECK(values() == std::vector<std::int32_t>{4});
    }
}

TEST_CASE("entries and replies from another thread are queued in order with one wake, on the strand sent at once") {
    auto pump = std::make_shared<KeepingPump>();
    auto session = std::make_shared<ServerSession>(1, 2, nullptr, pump, std::weak_ptr<ServerConnection>(), 1u << 20);
    const SessionRef ref(session);
    const auto event = [](std::int32_t v) {
        auto e = request(MessageEntryType::EventReq, "ev");
        e.elements.push_back(make_scalar_element<std::int32_t>("value", v));
        return std::make_shared<const EncodedEntry>(std::move(e));
    };
    std::vector<ServerSession::PendingSend> sends;
    std::vector<ServerSession::PendingWire> wires;

    // On the strand (or when the pump cannot tell): a dispatch per entry, as a reply's order needs.
    REQUIRE(ref.send(event(1)));
    CHECK(pump->held.size() == 1);
    CHECK(pump->wakes == 0);

    pump->off_strand = true;
    REQUIRE(ref.send(event(2)));
    REQUIRE(ref.send_wire_packet(wire_packet_with("w", 5)));
    REQUIRE(ref.send(event(3)));
    CHECK(pump->wakes == 1);  // one wake for the events and the wire packet
    CHECK(pump->held.size() == 1);
    session->take_queued(sends, wires);
    REQUIRE(sends.size() == 2);
    CHECK(pending_value(sends[0]) == 2);
    CHECK(pending_value(sends[1]) == 3);
    REQUIRE(wires.size() == 1);
    CHECK(pending_value(wires[0]) == 5);

    // Entries are never coalesced, and the next one wakes again.
    REQUIRE(ref.send(event(4)));
    REQUIRE(ref.send(event(4)));
    CHECK(pump->wakes == 2);
    session->take_queued(sends, wires);
    CHECK(sends.size() == 4);
    sends.clear();

    // The session's own entries and replies from other threads join the same queue, in the order sent,
    // on the same wake: a worker's event before its reply stays before it, and after it stays after.
    auto own = request(MessageEntryType::EventReq, "ev");
    own.elements.push_back(make_scalar_element<std::int32_t>("value", 10));
    REQUIRE(ref.send(std::move(own)));
    MessageEntry reply;
    reply.elements.push_back(make_scalar_element<std::int32_t>("value", 11));
    session->queue_reply(std::move(reply));
    REQUIRE(ref.send(event(12)));
    CHECK(pump->wakes == 3);
    CHECK(pump->held.size() == 1);  // no closure for any of them
    session->take_queued(sends, wires);
    REQUIRE(sends.size() == 3);
    CHECK(pending_send(sends[0]) == std::make_pair(std::string("own"), 10));
    CHECK(pending_send(sends[1]) == std::make_pair(std::string("reply"), 11));
    CHECK(pending_send(sends[2]) == std::make_pair(std::string("shared"), 12));

    // A reply for a session that has closed is dropped, not queued.
    session->mark_closed();
    MessageEntry late;
    session->queue_reply(std::move(late));
    sends.clear();
    session->take_queued(sends, wires);
    CHECK(sends.empty());

    // The send queue bound holds for queued entries too.
    auto small = std::make_shared<ServerSession>(1, 2, nullptr, pump, std::weak_ptr<ServerConnection>(), 256);
    Result<void> r;
    int accepted = 0;
    while ((r = SessionRef(small).send(event(9))) && accepted < 100) ++accepted;
    CHECK(accepted < 100);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::BufferLimitViolation);
}
