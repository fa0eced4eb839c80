// auth: passthrough and the device's locks at a client's disconnect: the client's DisconnectClient is
// answered only once the device has answered the DisconnectClient of the client's upstream session, so
// the locks of that session are gone on the device when the client's disconnect returns, as with a
// direct connection (CORE answers DisconnectClient after its RemoveClient). The official test suite's
// test_object_lock reads the object from another user's session right after DisconnectService of the
// lock holder; through the gateway it failed now and then when the device had not yet ended the
// holder's upstream session (issue 40).
//
// The device is an ObjectService with logins that takes 50 ms to end a session (its session close
// holds its strand before the DisconnectClientRet goes out), which widens that window from a few
// scheduling steps of the official device to every round.
#include <catch2/catch.hpp>

#include <thread>

#include "server/gateway/device_mirror.hpp"
#include "server/node/test_node.hpp"
#include "server/service/object_service_fixture.hpp"
#include "test/support/eventually.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::gateway;
using namespace rr::server::testing;
using namespace std::chrono_literals;
using rr::testing::eventually;

// Named, not anonymous: the TSan preset builds the tests as unity files.
namespace passthrough_locks_test {

/// An ObjectService whose sessions take `delay` to end: everything else is the inner service's.
class SlowToEndService : public Service {
public:
    SlowToEndService(std::shared_ptr<ObjectService> inner, std::chrono::milliseconds delay)
        : inner_(std::move(inner)), delay_(delay) {}

    const std::string& name() const override { return inner_->name(); }
    std::vector<std::string> service_definitions() const override { return inner_->service_definitions(); }
    std::optional<std::string> service_definition(std::string_view type) const override {
        return inner_->service_definition(type);
    }
    ObjectTypeInfo root_type() const override { return inner_->root_type(); }
    MessageElement attributes() const override { return inner_->attributes(); }
    void object_type(const SessionRef& session, const std::string& path,
                     std::function<void(Result<ObjectTypeInfo>)> done) override {
        inner_->object_type(session, path, std::move(done));
    }
    bool requires_authentication() const override { return inner_->requires_authentication(); }
    Result<void> authenticate(const std::string& username, const MessageElement* credentials) override {
        return inner_->authenticate(username, credentials);
    }
    bool handles_locks() const override { return inner_->handles_locks(); }
    void attach(boost::asio::io_context& io) override { inner_->attach(io); }
    void on_session_open(const SessionRef& session) override { inner_->on_session_open(session); }
    void on_session_close(const SessionRef& session) override {
        std::this_thread::sleep_for(delay_);  // on the session's strand: its DisconnectClientRet waits too
        inner_->on_session_close(session);
    }
    void handle_entry(const SessionRef& session, MessageEntry&& entry, rr::server::Responder responder) override {
        inner_->handle_entry(session, std::move(entry), std::move(responder));
    }

private:
    std::shared_ptr<ObjectService> inner_;
    std::chrono::milliseconds delay_;
};

struct SlowDevice {
    std::shared_ptr<ObjectService> service;
    std::shared_ptr<Node> node = test_node("slow.node");
    std::uint16_t port = 0;

    SlowDevice() {
        auto types = ServiceTypes::create({kObjTestDef});
        REQUIRE(types);
        auto root = ServiceObject::create(*types, "example.objtest.Thing").value();
        REQUIRE(root->set_property_value("value", Value::scalar(1.5)));
        service = ObjectService::create(kTestService, root).value();
        PasswordTable users;
        users.add_user("alice", "a", {"objectlock"});
        users.add_user("bob", "b", {"objectlock"});
        users.add_user("gateway", "g");
        service->set_users(std::move(users));
        REQUIRE(node->register_service(std::make_shared<SlowToEndService>(service, 50ms)));
        port = *listen_tcp(node, "127.0.0.1", 0);
    }
    ~SlowDevice() {
        node->shutdown();
        service->shutdown();
    }
};

struct PassthroughGateway {
    SlowDevice device;
    std::shared_ptr<Node> node = test_node("gateway.node");
    std::shared_ptr<DeviceMirror> mirror;
    std::uint16_t port = 0;

    PassthroughGateway() {
        DeviceConfig cfg;
        cfg.name = "dev";
        cfg.url = "rr+tcp://127.0.0.1:" + std::to_string(device.port) + "/?service=" + kTestService;
        cfg.username = "gateway";
        cfg.password = "g";
        cfg.auth = DeviceAuth::passthrough;
        mirror = DeviceMirror::create(node, cfg).value();
        mirror->start();
        port = *listen_tcp(node, "127.0.0.1", 0);
        REQUIRE(eventually([&] { return mirror->status().state == DeviceState::connected; }));
    }
    ~PassthroughGateway() {
        mirror->stop();
        node->shutdown();
    }

    std::shared_ptr<RawClient> connect(const char* user, const char* password) const {
        RawClientOptions o;
        o.username = user;
        o.password = password;
        std::promise<Result<std::shared_ptr<RawClient>>> p;
        auto url = parse_connection_url("rr+tcp://127.0.0.1:" + std::to_string(port) + "/?service=dev");
        REQUIRE(url);
        RawClient::connect(node->io_context().get_executor(), *url, std::move(o), {}, {},
                           [&](Result<std::shared_ptr<RawClient>> r) { p.set_value(std::move(r)); });
        auto f = p.get_future();
        REQUIRE(f.wait_for(30s) == std::future_status::ready);
        auto r = f.get();
        INFO((r ? std::string() : r.error().message));
        REQUIRE(r);
        return *r;
    }
};

Result<MessageEntry> call(RawClient& c, MessageEntry e) {
    std::promise<Result<MessageEntry>> p;
    c.request(std::move(e), [&](Result<MessageEntry> r) { p.set_value(std::move(r)); });
    auto f = p.get_future();
    REQUIRE(f.wait_for(30s) == std::future_status::ready);
    return f.get();
}

/// The error type of the answer to a read of the root's `value` (None: it was read).
MessageErrorType read_value(RawClient& c) {
    auto r = call(c, req(MessageEntryType::PropertyGetReq, "value", "dev"));
    REQUIRE(r);
    return r->error;
}

/// Disconnects `c` as an RR client does (DisconnectClient, waiting for its answer) and returns how long
/// that took.
std::chrono::milliseconds disconnect(RawClient& c) {
    std::promise<void> p;
    const auto start = std::chrono::steady_clock::now();
    c.close([&] { p.set_value(); });
    auto f = p.get_future();
    REQUIRE(f.wait_for(30s) == std::future_status::ready);
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start);
}

}  // namespace passthrough_locks_test
using namespace passthrough_locks_test;

// [timing]: a disconnect answered by the gateway is told from the client's own 500 ms wait by its duration.
TEST_CASE("auth passthrough: a client's disconnect returns once the device has released its session's locks", "[timing]") {
    PassthroughGateway gw;
    auto bob = gw.connect("bob", "b");
    REQUIRE(read_value(*bob) == MessageErrorType::None);
    constexpr int kRounds = 10;
    int refused_after_disconnect = 0;
    for (int round = 0; round < kRounds; ++round) {
        INFO("round " << round);
        // As test_object_lock: two sessions of one user, a user lock taken on the first; the second
        // closes (the lock stays: its user still has a session), then the first (the lock goes).
        auto a1 = gw.connect("alice", "a");
        auto a2 = gw.connect("alice", "a");
        auto locked = call(*a1, req(MessageEntryType::ClientSessionOpReq, "RequestObjectLock", "dev"));
        REQUIRE(locked);
        REQUIRE(locked->error == MessageErrorType::None);
        CHECK(read_value(*bob) == MessageErrorType::ObjectLockedError);
        CHECK(read_value(*a2) == MessageErrorType::None);
        // Each disconnect was answered by the gateway after the device's answer (50 ms of session end),
        // not by the client's own 500 ms wait for an answer that never came.
        CHECK(disconnect(*a2) < 400ms);
        CHECK(read_value(*bob) == MessageErrorType::ObjectLockedError);
        CHECK(disconnect(*a1) < 400ms);
        // At once, without waiting: the device has ended alice's last session, so her lock is gone.
        if (read_value(*bob) != MessageErrorType::None) ++refused_after_disconnect;
    }
    CHECK(refused_after_disconnect == 0);
    // The gateway's passthrough sessions went with their clients (bob's stays).
    CHECK(eventually([&] { return gw.mirror->status().upstream_sessions == 1; }));
    bob->close();
}
