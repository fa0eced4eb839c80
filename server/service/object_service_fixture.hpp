// Test-only: an ObjectService of example.objtest (every member kind) on a loopback node, and an
// entry-level client (RawClient) that collects what the service pushes.
#pragma once

#include <catch2/catch.hpp>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <mutex>

#include "core/session/elements.hpp"
#include "core/value/pack_value.hpp"
#include "robdef/parser.hpp"
#include "server/client/raw_client.hpp"
#include "server/node/node.hpp"
#include "server/service/callback_member.hpp"
#include "server/service/memory_member.hpp"
#include "server/service/object_service.hpp"
#include "server/service/pipe_member.hpp"
#include "server/service/wire_member.hpp"
#include "server/transport/tcp_listener.hpp"

namespace rr::server::testing {

using namespace std::chrono_literals;

inline constexpr const char* kObjTestDef = R"(service example.objtest

stdver 0.10

exception Fault

struct Pt
    field double x
    field double y
end

pod Sample
    field double t
    field int32[2] ids
end

namedarray V2
    field double a
    field double b
end

object Thing
    property double value
    property int32 ro [readonly]
    property int32 wo [writeonly]
    property string label
    function int32 add(int32 a, int32 b)
    function Pt mid(Pt a, Pt b)
    function void fail_user(string msg)
    function double later(double x)
    function void unimplemented()
    function void call_back(double x)
    function int32{generator} count(int32 n)
    function double{generator} sum(double{generator} v)
    function void sink(string{generator} s)
    event changed(double v, string why)
    objref Sub sub
    objref Sub{int32} subs
    objref Sub{string} named
    objref Sub[] listed
    objref Sub[]{string} listed_named
    objref varobject anything
    pipe double[] samples
    pipe string lossy [unreliable]
    pipe double feed [readonly]
    callback double ask(double x)
    callback void tell(string s)
    wire double[] level
    wire int32 in_only [writeonly]
    wire Pt state [readonly]
    memory double[] buf
    memory int32[*] grid
    memory Sample[] pods
    memory V2[*] nas
    memory uint8[] rom [readonly]
end

object Sub
    property int32 n
end
)";

inline constexpr const char* kTestService = "svc";
inline constexpr const char* kTestSvcDef = "example.objtest";

/// Entries the service pushed to a client, with waiting.
class Inbox {
public:
    void push(MessageEntry e) {
        {
            std::lock_guard lock(mutex_);
            entries_.push_back(std::move(e));
        }
        cv_.notify_all();
    }
    /// The first entry matching `pred` (removed from the inbox), waiting up to `timeout`.
    std::optional<MessageEntry> take(const std::function<bool(const MessageEntry&)>& pred,
                                     std::chrono::milliseconds timeout = 30000ms) {  // a bound on a hang
        std::unique_lock lock(mutex_);
        std::optional<MessageEntry> out;
        cv_.wait_for(lock, timeout, [&] {
            for (auto it = entries_.begin(); it != entries_.end(); ++it) {
                if (pred(*it)) {
                    out = std::move(*it);
                    entries_.erase(it);
                    return true;
                }
            }
            return false;
        });
        return out;
    }
    std::optional<MessageEntry> take(MessageEntryType type, std::chrono::milliseconds timeout = 30000ms) {  // a bound on a hang
        return take([type](const MessageEntry& e) { return e.entry_type == type; }, timeout);
    }
    std::size_t count(MessageEntryType type) {
        std::lock_guard lock(mutex_);
        std::size_t n = 0;
        for (const auto& e : entries_) n += e.entry_type == type;
        return n;
    }

private:
    std::mutex mutex_;
    std::condition_variable cv_;
    std::deque<MessageEntry> entries_;
};

struct TestClient {
    std::shared_ptr<RawClient> raw;
    std::shared_ptr<Inbox> inbox = std::make_shared<Inbox>();
    /// When set, called (on the client's strand) for every pushed entry instead of queueing it.
    std::shared_ptr<std::function<bool(MessageEntry&)>> hook = std::make_shared<std::function<bool(MessageEntry&)>>();

    Result<MessageEntry> call(MessageEntry e) const {
        std::promise<Result<MessageEntry>> p;
        raw->request(std::move(e), [&](Result<MessageEntry> r) { p.set_value(std::move(r)); });
        auto f = p.get_future();
        REQUIRE(f.wait_for(30s) == std::future_status::ready);
        return f.get();
    }
    /// A reply that must be a success.
    MessageEntry ok(MessageEntry e) const {
        auto r = call(std::move(e));
        REQUIRE(r);
        if (r->error != MessageErrorType::None) {
            auto err = entry_error(*r);
            FAIL("unexpected error " << int(r->error) << " " << (err ? err->message : std::string()));
        }
        return std::move(*r);
    }
    /// The error code of a reply that must be an error.
    RRError error(MessageEntry e) const {
        auto r = call(std::move(e));
        REQUIRE(r);
        REQUIRE(r->error != MessageErrorType::None);
        return *entry_error(*r);
    }
    void send(MessageEntry e) const { raw->send(std::move(e)); }
};

inline MessageEntry req(MessageEntryType type, std::string member, std::string path = kTestService) {
    MessageEntry e;
    e.entry_type = type;
    e.service_path = std::move(path);
    e.member_name = std::move(member);
    return e;
}

struct ServiceFixture {
    std::shared_ptr<const ServiceTypes> types;
    std::shared_ptr<ServiceObject> root;
    std::shared_ptr<ObjectService> service;
    std::shared_ptr<Node> node;
    std::uint16_t port = 0;

    /// `setup` runs before the service is created (attach handlers there or later).
    explicit ServiceFixture(const std::function<void(ServiceFixture&)>& setup = {}, NodeOptions options = {}) {
        auto t = ServiceTypes::create({kObjTestDef});
        INFO((t ? std::string() : t.error().message));
        REQUIRE(t);
        types = *t;
        root = ServiceObject::create(types, "example.objtest.Thing").value();
        if (setup) setup(*this);
        service = ObjectService::create(kTestService, root).value();
        if (options.threads == 0) options.threads = 2;
        node = Node::create(std::move(options));
        REQUIRE(node->register_service(service));
        auto p = listen_tcp(node, "127.0.0.1", 0);
        REQUIRE(p);
        port = *p;
    }
    ~ServiceFixture() {
        node->shutdown();
        service->shutdown();
    }

    TestClient connect(RawClientOptions opts = {}) const {
        auto c = try_connect(std::move(opts));
        INFO((c ? std::string() : c.error().message));
        REQUIRE(c);
        return std::move(*c);
    }
    Result<TestClient> try_connect(RawClientOptions opts = {}) const {
        TestClient c;
        std::promise<Result<std::shared_ptr<RawClient>>> p;
        auto url = parse_connection_url("rr+tcp://127.0.0.1:" + std::to_string(port) + "/?service=" + kTestService);
        REQUIRE(url);
        RawClient::connect(
            node->io_context().get_executor(), *url, std::move(opts),
            [inbox = c.inbox, hook = c.hook](MessageEntry&& e) {
                if (*hook && (*hook)(e)) return;
                inbox->push(std::move(e));
            },
            {}, [&](Result<std::shared_ptr<RawClient>> r) { p.set_value(std::move(r)); });
        auto f = p.get_future();
        REQUIRE(f.wait_for(30s) == std::future_status::ready);
        auto r = f.get();
        if (!r) return r.take_error();
        c.raw = *r;
        return c;
    }

    /// Packs `v` as robdef type text `type` (e.g. "Pt", "double[]").
    MessageElement pack(const Value& v, std::string_view type, std::string_view name) const {
        auto t = robdef::parse_type(type);
        REQUIRE(t);
        auto e = pack_value(v, *t, name, types->set(), kTestSvcDef);
        INFO((e ? std::string() : e.error().message));
        REQUIRE(e);
        return *e;
    }
    Value unpack(const MessageElement& e, std::string_view type) const {
        auto t = robdef::parse_type(type);
        REQUIRE(t);
        auto v = unpack_value(e, *t, types->set(), kTestSvcDef);
        INFO((v ? std::string() : v.error().message));
        REQUIRE(v);
        return *v;
    }
};

inline Value pt(double x, double y) {
    Structure s;
    s.type_name = "example.objtest.Pt";
    s.set("x", Value::scalar(x));
    s.set("y", Value::scalar(y));
    return Value(std::move(s));
}

template <class T>
T scalar_of(const MessageEntry& e, std::string_view name) {
    const auto* el = e.find(name);
    REQUIRE(el);
    T v{};
    REQUIRE(read_scalar(*el, v));
    return v;
}

}  // namespace rr::server::testing
