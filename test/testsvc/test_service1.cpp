// TestService1.testroot and its objects (sub1, sub2, sub3, TestService2.subobj): RobotRaconteurTestService
// and RobotRaconteurTestService_auth.
#include <atomic>
#include <map>
#include <mutex>

#include "server/service/callback_member.hpp"
#include "server/service/memory_member.hpp"
#include "server/service/pipe_member.hpp"
#include "server/service/wire_member.hpp"
#include "test/testsvc/test_services.hpp"

namespace rr::testsvc {

using namespace rr::server;

namespace {

Value dbl(double d) { return Value::scalar<double>(d); }

Value teststruct2(double d) {
    Structure s;
    s.type_name = kTs1 + ".teststruct2";
    s.set("mydat", Value(NumericArray::from<double>({d})));
    return Value(std::move(s));
}

Result<double> as_double(const Value& v) { return v.as<double>(); }

// --- sub3, sub2, sub1, subobj: objects reached through objrefs, created on first use ----------------

struct Sub3 {
    std::shared_ptr<ServiceObject> obj;
};

std::shared_ptr<Sub3> make_sub3(const Context& c, const std::string& type, const std::string& ind) {
    auto h = std::make_shared<Sub3>();
    h->obj = make_object(c, type);
    must(h->obj->set_property_value("ind", Value(ind)), "sub3.ind");
    must(h->obj->set_property_value("data2", Value(std::string())), "sub3.data2");
    must(h->obj->set_property_value("data3", dbl(0)), "sub3.data3");
    must(h->obj->set_function("add",
                              [](const SessionRef&, std::vector<Value> a) -> Result<Value> {
                                  auto d = as_double(a[0]);
                                  if (!d) return d.take_error();
                                  return dbl(*d + 42);
                              }),
         "sub3.add");
    return h;
}

/// Objects made on first request of an index, kept for later ones (the official services do the same).
template <class Key, class Holder>
class ByIndex {
public:
    template <class Make>
    std::shared_ptr<Holder> get(const Key& k, Make make) {
        std::lock_guard lock(mutex_);
        auto& slot = items_[k];
        if (!slot) slot = make();
        return slot;
    }

private:
    std::mutex mutex_;
    std::map<Key, std::shared_ptr<Holder>> items_;
};

template <class Key>
Result<Key> index_as(const ObjRefIndex& i) {
    if (const Key* k = std::get_if<Key>(&i)) return *k;
    return fail(MessageErrorType::ObjectNotFound, "wrong index kind");
}

struct Sub2 {
    std::shared_ptr<ServiceObject> obj;
    ByIndex<std::string, Sub3> o3_1;
};

/// `type`: TestService1.sub2, or TestService3.obj4 (which implements it).
std::shared_ptr<Sub2> make_sub2(const Context& c, const std::string& type, const std::string& s_ind, std::int32_t i_ind) {
    auto h = std::make_shared<Sub2>();
    h->obj = make_object(c, type);
    must(h->obj->set_property_value("s_ind", Value(s_ind)), "sub2.s_ind");
    must(h->obj->set_property_value("i_ind", Value::scalar<std::int32_t>(i_ind)), "sub2.i_ind");
    must(h->obj->set_property_value("data", Value(std::string())), "sub2.data");
    std::weak_ptr<Sub2> weak = h;
    must(h->obj->set_objref("o3_1",
                            [weak, c](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
                                auto self = weak.lock();
                                auto k = index_as<std::string>(i);
                                if (!self || !k) return fail(MessageErrorType::ObjectNotFound, "no such object");
                                return self->o3_1.get(*k, [&] { return make_sub3(c, kTs1 + ".sub3", *k); })->obj;
                            }),
         "sub2.o3_1");
    return h;
}

struct Sub1 {
    std::shared_ptr<ServiceObject> obj;
    std::shared_ptr<Sub2> o2_1;
    ByIndex<std::int32_t, Sub2> o2_2;
    ByIndex<std::string, Sub2> o2_3;
};

std::shared_ptr<Sub1> make_sub1(const Context& c, const std::string& s_ind, std::int32_t i_ind) {
    auto h = std::make_shared<Sub1>();
    h->obj = make_object(c, kTs1 + ".sub1");
    must(h->obj->set_property_value("d1", Value(NumericArray::from<double>({}))), "sub1.d1");
    must(h->obj->set_property_value("s_ind", Value(s_ind)), "sub1.s_ind");
    must(h->obj->set_property_value("i_ind", Value::scalar<std::int32_t>(i_ind)), "sub1.i_ind");
    h->o2_1 = make_sub2(c, kTs1 + ".sub2", "", 0);
    std::weak_ptr<Sub1> weak = h;
    must(h->obj->set_objref("o2_1",
                            [weak](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
                                auto self = weak.lock();
                                if (!self) return fail(MessageErrorType::ObjectNotFound, "no such object");
                                return self->o2_1->obj;
                            }),
         "sub1.o2_1");
    must(h->obj->set_objref("o2_2",
                            [weak, c](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
                                auto self = weak.lock();
                                auto k = index_as<std::int32_t>(i);
                                if (!self || !k) return fail(MessageErrorType::ObjectNotFound, "no such object");
                                return self->o2_2.get(*k, [&] { return make_sub2(c, kTs1 + ".sub2", "", *k); })->obj;
                            }),
         "sub1.o2_2");
    must(h->obj->set_objref("o2_3",
                            [weak, c](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
                                auto self = weak.lock();
                                auto k = index_as<std::string>(i);
                                if (!self || !k) return fail(MessageErrorType::ObjectNotFound, "no such object");
                                return self->o2_3.get(*k, [&] { return make_sub2(c, kTs1 + ".sub2", *k, 0); })->obj;
                            }),
         "sub1.o2_3");
    return h;
}

std::shared_ptr<ServiceObject> make_subobj(const Context& c) {
    auto o = make_object(c, kTs2 + ".subobj");
    must(o->set_function("add_val",
                         [](const SessionRef&, std::vector<Value> a) -> Result<Value> {
                             auto d = as_double(a[0]);
                             if (!d) return d.take_error();
                             return dbl(*d + 1);
                         }),
         "subobj.add_val");
    return o;
}

constexpr std::int32_t kHugeLength = 2621440;  // i32_huge: 10 MiB of int32

}  // namespace

struct TestRoot::State {
    Context c;
    std::shared_ptr<ServiceObject> root;
    std::weak_ptr<ObjectService> service;

    std::shared_ptr<Sub1> o1;
    ByIndex<std::int32_t, Sub1> o2, o3;
    ByIndex<std::string, Sub1> o4;
    std::shared_ptr<ServiceObject> o5;

    std::mutex o6_mutex;
    std::shared_ptr<void> o6_holder;  // the Sub1 / Sub2 behind o6 (its objrefs need it alive)
    std::shared_ptr<ServiceObject> o6;

    // p1: the first packet echoed to each session is sent asking for an ack; pipe_check_error wants it.
    struct PipeAck {
        std::uint32_t first = 0;
        bool sent = false, acked = false;
    };
    std::mutex p1_mutex;
    std::map<std::uint32_t, PipeAck> p1_acks;  // by session endpoint

    // broadcastpipe: at most 3 unacknowledged packets per endpoint (the official PipeBroadcaster backlog).
    std::mutex bp_mutex;
    std::map<const PipeEndpoint*, int> bp_in_flight;

    std::shared_ptr<PipeMember> broadcastpipe;
    std::shared_ptr<WireMember> broadcastwire;
    std::shared_ptr<CallbackMember> cb1, cb2, cb3, cb_meaning_of_life, cb_errtest;

    void build();
    void o6_op(std::int32_t op);
    void test_callbacks(const SessionRef& session, Completion done);
};

void TestRoot::State::build() {
    root = make_object(c, kTs1 + ".testroot");
    serve_table_properties(c, *root, {"i32_huge", "errtest", "nulltest"});

    // i32_huge: 0, 1, 2, … on get; a set must send 0, -1, -2, …
    auto huge = std::make_shared<Value>([] {
        std::vector<std::int32_t> v(kHugeLength);
        for (std::int32_t i = 0; i < kHugeLength; ++i) v[i] = i;
        return Value(NumericArray::adopt<std::int32_t>(std::move(v)));
    }());
    must(root->set_property_handlers(
             "i32_huge", [huge](const SessionRef&) -> Result<Value> { return *huge; },
             [](const SessionRef&, Value v) -> Result<void> {
                 const auto* a = v.get_if<NumericArray>();
                 if (!a || a->type() != DataTypes::int32_t || a->size() != kHugeLength)
                     return fail(MessageErrorType::InvalidArgument, "i32_huge: expected 2621440 int32");
                 auto items = a->view<std::int32_t>();
                 for (std::int32_t i = 0; i < kHugeLength; ++i)
                     if (items[i] != -i) return fail(MessageErrorType::InvalidArgument, "i32_huge: item " + std::to_string(i) + " is not -" + std::to_string(i));
                 return {};
             }),
         "i32_huge");
    must(root->set_property_handlers(
             "errtest",
             [](const SessionRef&) -> Result<Value> { return fail(MessageErrorType::OperationFailed, "errtest always fails"); },
             [](const SessionRef&, Value) -> Result<void> { return fail(MessageErrorType::OperationFailed, "errtest always fails"); }),
         "errtest");
    must(root->set_property_handlers(
             "nulltest", [](const SessionRef&) -> Result<Value> { return Value(); },
             [](const SessionRef&, Value v) -> Result<void> {
                 if (!v.is_null()) return fail(MessageErrorType::InvalidArgument, "nulltest: only null may be set");
                 return {};
             }),
         "nulltest");

    // functions
    State* self = this;
    auto fn = [&](const char* name, FunctionHandler h) { must(root->set_function(name, std::move(h)), name); };
    fn("func1", [self](const SessionRef&, std::vector<Value>) -> Result<Value> {
        after(*self->c.io, std::chrono::milliseconds(10), [self] { (void)self->root->fire_event("ev1", {}); });
        return Value();
    });
    fn("func2", [self](const SessionRef&, std::vector<Value> a) -> Result<Value> {
        auto d1 = as_double(a[0]);
        auto d2 = as_double(a[1]);
        if (!d1 || !d2) return fail(MessageErrorType::InvalidArgument, "func2: doubles expected");
        after(*self->c.io, std::chrono::milliseconds(10),
              [self, d1 = *d1, d2 = *d2] { (void)self->root->fire_event("ev2", {dbl(d1), teststruct2(d2)}); });
        return Value();
    });
    auto add = [](const SessionRef&, std::vector<Value> a) -> Result<Value> {
        auto d1 = as_double(a[0]);
        auto d2 = as_double(a[1]);
        if (!d1 || !d2) return fail(MessageErrorType::InvalidArgument, "func3: doubles expected");
        return dbl(*d1 + *d2);
    };
    fn("func3", add);
    fn("meaning_of_life", [](const SessionRef&, std::vector<Value>) -> Result<Value> { return Value::scalar<std::int32_t>(42); });
    fn("func_errtest", [](const SessionRef&, std::vector<Value>) -> Result<Value> {
        return fail(MessageErrorType::OperationFailed, "This is a test");
    });
    fn("func_errtest1", [](const SessionRef&, std::vector<Value>) -> Result<Value> {
        return fail(MessageErrorType::DataTypeError, "This is a test 1");
    });
    fn("func_errtest2", [self](const SessionRef&, std::vector<Value>) -> Result<Value> {
        return fail(self->root->user_error("testexception1", "This is a test 2"));
    });
    fn("func_errtest3", [self](const SessionRef&, std::vector<Value>) -> Result<Value> {
        return fail(self->root->user_error(kTs2 + ".testexception3", "This is a test 3"));
    });

    // objrefs
    o1 = make_sub1(c, "", 0);
    o5 = make_subobj(c);
    must(root->set_objref("o1", [self](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
             return self->o1->obj;
         }),
         "o1");
    must(root->set_objref("o2", [self](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
             auto k = index_as<std::int32_t>(i);
             if (!k) return k.take_error();
             return self->o2.get(*k, [&] { return make_sub1(self->c, "", *k); })->obj;
         }),
         "o2");
    must(root->set_objref("o3", [self](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
             auto k = index_as<std::int32_t>(i);
             if (!k) return k.take_error();
             return self->o3.get(*k, [&] { return make_sub1(self->c, "", *k); })->obj;
         }),
         "o3");
    must(root->set_objref("o4", [self](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
             auto k = index_as<std::string>(i);
             if (!k) return k.take_error();
             return self->o4.get(*k, [&] { return make_sub1(self->c, *k, 0); })->obj;
         }),
         "o4");
    must(root->set_objref("o5", [self](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
             return self->o5;
         }),
         "o5");
    {
        auto first = make_sub1(c, "", 0);
        o6 = first->obj;
        o6_holder = first;
    }
    must(root->set_objref("o6", [self](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
             std::lock_guard lock(self->o6_mutex);
             return self->o6;
         }),
         "o6");
    fn("o6_op", [self](const SessionRef&, std::vector<Value> a) -> Result<Value> {
        auto op = a[0].as<std::int32_t>();
        if (!op) return op.take_error();
        if (*op < 0 || *op > 2) return fail(MessageErrorType::InvalidArgument, "o6_op: op must be 0, 1 or 2");
        self->o6_op(*op);
        return Value();
    });

    // pipes
    auto p1 = must(root->pipe("p1"), "p1");
    p1->on_packet([self](const std::shared_ptr<PipeEndpoint>& ep, Value packet) {
        std::lock_guard lock(self->p1_mutex);  // held across send: the first packet number is this send's
        auto& ack = self->p1_acks[ep->session().endpoint()];
        auto n = ep->send(packet, true);
        if (n && !ack.sent) {
            ack.sent = true;
            ack.first = *n;
        }
    });
    p1->on_ack([self](const std::shared_ptr<PipeEndpoint>& ep, std::uint32_t number) {
        std::lock_guard lock(self->p1_mutex);
        auto& ack = self->p1_acks[ep->session().endpoint()];
        if (ack.sent && ack.first == number) ack.acked = true;
    });
    std::weak_ptr<PipeMember> weak_p1 = p1;
    p1->on_close([self, weak_p1](const std::shared_ptr<PipeEndpoint>& ep) {
        auto pipe = weak_p1.lock();
        if (!pipe) return;
        const auto e = ep->session().endpoint();
        for (const auto& other : pipe->endpoints())
            if (other->session().endpoint() == e) return;  // the session still has a p1 endpoint
        std::lock_guard lock(self->p1_mutex);
        self->p1_acks.erase(e);
    });
    fn("pipe_check_error", [self](const SessionRef& session, std::vector<Value>) -> Result<Value> {
        std::lock_guard lock(self->p1_mutex);
        auto it = self->p1_acks.find(session.endpoint());
        if (it == self->p1_acks.end() || !it->second.acked)
            return fail(MessageErrorType::InvalidOperation, "p1: the first packet echoed to this client was not acknowledged");
        return Value();
    });
    auto p2 = must(root->pipe("p2"), "p2");
    p2->on_packet([](const std::shared_ptr<PipeEndpoint>& ep, Value packet) { (void)ep->send(packet); });
    broadcastpipe = must(root->pipe("broadcastpipe"), "broadcastpipe");
    broadcastpipe->on_ack([self](const std::shared_ptr<PipeEndpoint>& ep, std::uint32_t) {
        std::lock_guard lock(self->bp_mutex);
        if (auto it = self->bp_in_flight.find(ep.get()); it != self->bp_in_flight.end() && it->second > 0) --it->second;
    });
    broadcastpipe->on_close([self](const std::shared_ptr<PipeEndpoint>& ep) {
        std::lock_guard lock(self->bp_mutex);
        self->bp_in_flight.erase(ep.get());
    });

    // callbacks
    cb1 = must(root->callback("cb1"), "cb1");
    cb2 = must(root->callback("cb2"), "cb2");
    cb3 = must(root->callback("cb3"), "cb3");
    cb_meaning_of_life = must(root->callback("cb_meaning_of_life"), "cb_meaning_of_life");
    cb_errtest = must(root->callback("cb_errtest"), "cb_errtest");
    must(root->set_async_function("test_callbacks",
                                  [self](const SessionRef& session, std::vector<Value>, Completion done) {
                                      self->test_callbacks(session, std::move(done));
                                  }),
         "test_callbacks");

    // wires: each connection's value comes back to it as its in value
    for (const char* name : {"w1", "w2", "w3"}) {
        auto w = must(root->wire(name), name);
        w->on_value([](const std::shared_ptr<WireConnection>& conn, const Value& v, TimeSpec) {
            if (conn) (void)conn->set_out_value(v);
        });
    }
    broadcastwire = must(root->wire("broadcastwire"), "broadcastwire");
    must(broadcastwire->set_out_value(dbl(0)), "broadcastwire");

    // memories
    auto m1 = must(root->memory("m1"), "m1");
    auto m1_init = c.values->memory(root->type(), "m1");
    must(m1->set_contents(m1_init ? *m1_init : must(c.values->lfsr("double[100]", "m1_init"), "m1")), "m1");
    must(must(root->memory("m2"), "m2")->set_contents(zero_numbers(DataTypes::double_t, 100000, {10, 10, 10, 10, 10})), "m2");
    must(must(root->memory("m3"), "m3")->set_contents(zero_numbers(DataTypes::uint8_t, 1024 * 1024, {1024, 1024})), "m3");
}

void TestRoot::State::o6_op(std::int32_t op) {
    if (auto svc = service.lock())
        for (const auto& p : root->paths()) (void)svc->release_path(p + ".o6");  // nothing there yet: fine
    std::shared_ptr<void> holder;
    std::shared_ptr<ServiceObject> obj;
    if (op == 0) {
        auto h = make_sub1(c, "", 0);
        obj = h->obj;
        holder = h;
    } else if (op == 1) {
        auto h = make_sub2(c, kTs1 + ".sub2", "", 0);
        obj = h->obj;
        holder = h;
    } else {
        obj = make_subobj(c);
    }
    std::shared_ptr<void> old_holder;
    std::shared_ptr<ServiceObject> old;
    {
        std::lock_guard lock(o6_mutex);
        old_holder = std::exchange(o6_holder, std::move(holder));
        old = std::exchange(o6, std::move(obj));
    }
    old->clear_handlers();  // released: nothing reaches it any more
}

void TestRoot::State::test_callbacks(const SessionRef& session, Completion done) {
    // cb1(); cb2(739.2, 0.392); cb3(34, 45) must return 34 + 45 + 3.14; cb_meaning_of_life() 42;
    // cb_errtest() must fail. Each call waits for the one before.
    State* self = this;
    auto step5 = [self, session, done](Result<Value> r) {
        if (!r) return done(r.take_error());
        auto v = r->as<std::int32_t>();
        if (!v || *v != 42) return done(fail(MessageErrorType::InvalidArgument, "cb_meaning_of_life did not return 42"));
        self->cb_errtest->call(session, {}, [done](Result<Value> r2) {
            if (r2) return done(fail(MessageErrorType::InvalidOperation, "cb_errtest did not fail"));
            done(Value());
        });
    };
    auto step4 = [self, session, done, step5](Result<Value> r) {
        if (!r) return done(r.take_error());
        auto v = r->as<double>();
        if (!v || *v != 34.0 + 45.0 + 3.14) return done(fail(MessageErrorType::InvalidArgument, "cb3 did not return d1 + d2 + 3.14"));
        self->cb_meaning_of_life->call(session, {}, step5);
    };
    auto step3 = [self, session, done, step4](Result<Value> r) {
        if (!r) return done(r.take_error());
        self->cb3->call(session, {dbl(34), dbl(45)}, step4);
    };
    cb1->call(session, {}, [self, session, done, step3](Result<Value> r) {
        if (!r) return done(r.take_error());
        self->cb2->call(session, {dbl(739.2), dbl(0.392)}, step3);
    });
}

TestRoot::TestRoot(std::unique_ptr<State> state) : s_(std::move(state)) {}
TestRoot::~TestRoot() = default;

std::shared_ptr<TestRoot> TestRoot::create(const Context& c) {
    auto s = std::make_unique<State>();
    s->c = c;
    s->build();
    return std::shared_ptr<TestRoot>(new TestRoot(std::move(s)));
}

const std::shared_ptr<ServiceObject>& TestRoot::root() const { return s_->root; }

void TestRoot::attach(const std::shared_ptr<ObjectService>& service) { s_->service = service; }

void TestRoot::tick() {
    // broadcastpipe: packets 0…99 to every endpoint with fewer than 3 unacknowledged
    for (const auto& ep : s_->broadcastpipe->endpoints()) {
        for (int i = 0; i < 100; ++i) {
            {
                std::lock_guard lock(s_->bp_mutex);
                int& n = s_->bp_in_flight[ep.get()];
                if (n >= 3) break;
                ++n;
            }
            if (!ep->send(dbl(i), true)) {
                std::lock_guard lock(s_->bp_mutex);
                --s_->bp_in_flight[ep.get()];
                break;
            }
        }
    }
    // broadcastwire: 0…99 (a client sees the newest)
    if (!s_->broadcastwire->connections().empty())
        for (int i = 0; i < 100; ++i) (void)s_->broadcastwire->set_out_value(dbl(i));
}

}  // namespace rr::testsvc

namespace rr::testsvc {

/// TestService3.obj4 implements TestService1.sub2 and behaves as one (test_service3.cpp).
std::shared_ptr<void> make_obj4_holder(const Context& c, std::shared_ptr<server::ServiceObject>& object) {
    auto h = make_sub2(c, kTs3 + ".obj4", "", 0);
    object = h->obj;
    return h;
}

}  // namespace rr::testsvc
