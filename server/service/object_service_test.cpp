// ObjectService + ServiceObject at the entry level, over loopback TCP with RawClient: connection
// details, properties, functions, events, objrefs, callbacks, authentication and dispatch errors.
#include "server/service/object_service_fixture.hpp"

#include <thread>

#include "robdef/parser.hpp"

using namespace rr;
using namespace rr::server;
using namespace rr::server::testing;

TEST_CASE("ServiceTypes: verified definitions, lookups and user errors") {
    auto bad = ServiceTypes::create({"service example.bad\n\nstdver 0.10\n\nobject A\n    property Nope x\nend\n"});
    REQUIRE_FALSE(bad);
    CHECK(bad.error().type == MessageErrorType::ServiceDefinitionError);
    auto broken = ServiceTypes::create({"service example.bad\nobject"});
    REQUIRE_FALSE(broken);
    CHECK(broken.error().type == MessageErrorType::ServiceDefinitionError);

    const std::string base = "service example.base\n\nstdver 0.10\n\nobject B\n    property int32 n\nend\n";
    const std::string top = "service example.top\n\nstdver 0.10\n\nimport example.base\n\nusing example.base.B\n\n"
                            "object T\n    implements B\n    property int32 n\nend\n";
    auto types = ServiceTypes::create({top, base});
    INFO((types ? std::string() : types.error().message));
    REQUIRE(types);
    CHECK((*types)->texts_for("example.top") == std::vector<std::string>{top, base});
    CHECK((*types)->implements_of("example.top.T") == std::vector<std::string>{"example.base.B"});
    CHECK((*types)->object_is_a("example.top.T", "example.base.B"));
    CHECK_FALSE((*types)->object_is_a("example.base.B", "example.top.T"));
    CHECK((*types)->text("example.base") == base);

    auto t = ServiceTypes::create({kObjTestDef}).value();
    auto user = t->user_error("Fault", "boom", "example.objtest");
    CHECK(user.type == MessageErrorType::RemoteError);
    CHECK(user.name == "example.objtest.Fault");
    CHECK(t->user_error("NoSuch", "x", "example.objtest").type == MessageErrorType::InternalError);
    CHECK_FALSE(ServiceObject::create(t, "example.objtest.Nope"));
    CHECK_FALSE(ServiceObject::create(t, "example.objtest.Pt"));
}

TEST_CASE("ObjectService: connect reply, definitions, attributes, object types") {
    ServiceFixture f;
    MapString attrs;
    attrs.entries.emplace_back("purpose", Value("test"));
    attrs.entries.emplace_back("version", Value::array<std::int32_t>({1, 2}));
    REQUIRE(f.service->set_attributes(attrs));
    for (bool v4 : {true, false}) {
        RawClientOptions opts;
        opts.enable_message4 = v4;
        auto c = f.connect(opts);
        CHECK(c.raw->info().object_type == "example.objtest.Thing");
        CHECK(c.raw->info().service_definitions == std::vector<std::string>{kObjTestDef});
        const auto& a = c.raw->info().attributes;
        REQUIRE(a.type == DataTypes::dictionary_t);
        REQUIRE(a.find("purpose"));
        CHECK(read_string(*a.find("purpose")) == "test");
        CHECK(read_array<std::int32_t>(*a.find("version")) == std::vector<std::int32_t>{1, 2});

        auto type = c.ok(req(MessageEntryType::ObjectTypeName, "", "svc"));
        CHECK(read_string(*type.find("objecttype")) == "example.objtest.Thing");
    }
    CHECK(f.service->service_definition("example.objtest") == std::string(kObjTestDef));
    CHECK_FALSE(f.service->service_definition("example.other"));
    CHECK_FALSE(ObjectService::create("bad name", ServiceObject::create(f.types, "example.objtest.Thing").value()));
    // a root already served elsewhere cannot be the root of a second service
    CHECK_FALSE(ObjectService::create("other", f.root));
}

TEST_CASE("members: each member is found by its name, and no other name is") {
    auto types = ServiceTypes::create({kObjTestDef}).value();
    auto thing = ServiceObject::create(types, "example.objtest.Thing").value();
    // Names of equal length (add, mid, sub, ask, buf, nas…) are told apart byte by byte; the rest by length.
    const char* members[] = {"value", "ro", "wo", "label", "add", "mid", "fail_user", "later", "unimplemented",
                             "call_back", "count", "sum", "sink", "changed", "sub", "subs", "named", "listed",
                             "listed_named", "anything", "samples", "lossy", "feed", "ask", "tell", "level",
                             "in_only", "state", "buf", "grid", "pods", "nas", "rom"};
    for (const char* name : members) {
        INFO(name);
        auto info = thing->member_info(name);
        REQUIRE(info);
        CHECK(info->def->name == name);
    }
    for (const char* other : {"", "a", "ad", "adc", "ade", "zzz", "aaa", "Add", "adds", "values", "listed_name",
                              "listed_namedx", "unimplementeD"})
        CHECK_FALSE(thing->member_info(other));
}

TEST_CASE("requests to the root object fail with ObjectNotFound once the service is shut down") {
    ServiceFixture f([](ServiceFixture& f) {
        REQUIRE(f.root->set_function("add", [](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            return Value::scalar<std::int32_t>(*a[0].as<std::int32_t>() + *a[1].as<std::int32_t>());
        }));
    });
    auto c = f.connect();
    auto add = req(MessageEntryType::FunctionCallReq, "add");
    add.elements.push_back(make_scalar_element<std::int32_t>("a", 1));
    add.elements.push_back(make_scalar_element<std::int32_t>("b", 2));
    CHECK(scalar_of<std::int32_t>(c.ok(add), "return") == 3);
    f.service->shutdown();
    CHECK(c.error(add).type == MessageErrorType::ObjectNotFound);
}

TEST_CASE("properties: stored value, handlers, direction and type errors") {
    ServiceFixture f([](ServiceFixture& f) {
        REQUIRE(f.root->set_property_value("value", Value::scalar(1.5)));
        REQUIRE(f.root->set_property_value("ro", Value::scalar<std::int32_t>(7)));
    });
    std::atomic<std::int32_t> written{0};
    REQUIRE(f.root->set_property_handlers("wo", {}, [&](const SessionRef&, Value v) -> Result<void> {
        written = *v.as<std::int32_t>();
        return {};
    }));
    auto c = f.connect();

    auto get = c.ok(req(MessageEntryType::PropertyGetReq, "value"));
    CHECK(scalar_of<double>(get, "value") == 1.5);
    auto set = req(MessageEntryType::PropertySetReq, "value");
    set.elements.push_back(make_scalar_element("value", -2.25));
    c.ok(set);
    CHECK(scalar_of<double>(c.ok(req(MessageEntryType::PropertyGetReq, "value")), "value") == -2.25);
    CHECK(*f.root->property_value("value")->as<double>() == -2.25);

    SECTION("readonly set, writeonly get") {
        auto ro = req(MessageEntryType::PropertySetReq, "ro");
        ro.elements.push_back(make_scalar_element<std::int32_t>("value", 1));
        CHECK(c.error(ro).type == MessageErrorType::ReadOnlyMember);
        CHECK(scalar_of<std::int32_t>(c.ok(req(MessageEntryType::PropertyGetReq, "ro")), "value") == 7);
        auto wo = req(MessageEntryType::PropertySetReq, "wo");
        wo.elements.push_back(make_scalar_element<std::int32_t>("value", 99));
        c.ok(wo);
        CHECK(written == 99);
        CHECK(c.error(req(MessageEntryType::PropertyGetReq, "wo")).type == MessageErrorType::WriteOnlyMember);
    }
    SECTION("wrong type, missing value, no value, unknown member, wrong kind") {
        auto bad = req(MessageEntryType::PropertySetReq, "value");
        bad.elements.push_back(make_string_element("value", "x"));
        CHECK(c.error(bad).type == MessageErrorType::DataTypeError);
        auto arr = req(MessageEntryType::PropertySetReq, "value");
        arr.elements.push_back(make_array_element<double>("value", std::vector<double>{1, 2}));
        CHECK(c.error(arr).type == MessageErrorType::DataTypeError);
        auto missing = c.error(req(MessageEntryType::PropertySetReq, "value"));
        CHECK(missing.type == MessageErrorType::MessageElementNotFound);
        CHECK(missing.message == "Element value not found.");
        CHECK(c.error(req(MessageEntryType::PropertyGetReq, "label")).type == MessageErrorType::ValueNotSet);
        auto unknown = c.error(req(MessageEntryType::PropertyGetReq, "nosuch"));
        CHECK(unknown.type == MessageErrorType::MemberNotFound);
        CHECK(unknown.message == "Member nosuch not found");
        CHECK(c.error(req(MessageEntryType::PropertyGetReq, "add")).type == MessageErrorType::MemberNotFound);
        CHECK(c.error(req(MessageEntryType::FunctionCallReq, "value")).type == MessageErrorType::MemberNotFound);
    }
    SECTION("getter errors pass through; values of the wrong type are refused when stored") {
        REQUIRE(f.root->set_property_handlers("label", [](const SessionRef&) -> Result<Value> {
            return fail(MessageErrorType::InvalidOperation, "not now");
        }));
        auto e = c.error(req(MessageEntryType::PropertyGetReq, "label"));
        CHECK(e.type == MessageErrorType::InvalidOperation);
        CHECK(e.message == "not now");
        CHECK_FALSE(f.root->set_property_value("value", Value("text")));
        CHECK(f.root->set_property_value("nosuch", Value::scalar(1.0)).error().type == MessageErrorType::MemberNotFound);
        CHECK(f.root->set_property_value("add", Value::scalar(1.0)).error().type == MessageErrorType::MemberNotFound);
    }
}

TEST_CASE("properties: asynchronous getter and setter answer later, from another thread") {
    ServiceFixture f;
    std::atomic<std::int32_t> written{0};
    REQUIRE(f.root->set_async_property_handlers(
        "label",
        [](const SessionRef&, Completion done) {
            std::thread([done = std::move(done)] {
                done(Value("later"));
                done(Value("twice"));  // a second completion is ignored
            }).detach();
        },
        [&written](const SessionRef&, Value v, SetCompletion done) {
            const std::string s = *v.as<std::string>();
            std::thread([&written, s, done = std::move(done)] {
                if (s == "bad") {
                    done(fail(MessageErrorType::InvalidArgument, "no bad labels"));
                    return;
                }
                written = static_cast<std::int32_t>(s.size());
                done({});
            }).detach();
        }));
    auto c = f.connect();
    auto get = c.ok(req(MessageEntryType::PropertyGetReq, "label"));
    CHECK(read_string(*get.find("value")) == "later");
    auto set = req(MessageEntryType::PropertySetReq, "label");
    set.elements.push_back(make_string_element("value", "four"));
    c.ok(set);
    CHECK(written == 4);
    auto bad = req(MessageEntryType::PropertySetReq, "label");
    bad.elements.push_back(make_string_element("value", "bad"));
    auto e = c.error(bad);
    CHECK(e.type == MessageErrorType::InvalidArgument);
    CHECK(e.message == "no bad labels");

    SECTION("a value of the wrong type from the async getter is answered with the packing error") {
        REQUIRE(f.root->set_async_property_handlers("value", [](const SessionRef&, Completion done) { done(Value("x")); }));
        CHECK(c.error(req(MessageEntryType::PropertyGetReq, "value")).type == MessageErrorType::DataTypeMismatch);
    }
    SECTION("synchronous handlers replace the asynchronous ones") {
        REQUIRE(f.root->set_property_handlers("label", [](const SessionRef&) -> Result<Value> { return Value("now"); }));
        CHECK(read_string(*c.ok(req(MessageEntryType::PropertyGetReq, "label")).find("value")) == "now");
    }
}

TEST_CASE("functions: an error with a sub-name and a parameter reaches the client with both") {
    ServiceFixture f([](ServiceFixture& f) {
        auto* fixture = &f;
        REQUIRE(f.root->set_function("unimplemented", [fixture](const SessionRef&, std::vector<Value>) -> Result<Value> {
            RRError e = make_error(MessageErrorType::InvalidOperation, "test error");
            e.sub_name = "my_error";
            MapString params;
            params.entries.emplace_back("param1", Value::scalar<std::int32_t>(10));
            params.entries.emplace_back("param2", Value("20"));
            e.param = std::make_shared<const MessageElement>(fixture->pack(Value(std::move(params)), "varvalue", "p"));
            return fail(std::move(e));
        }));
    });
    auto c = f.connect();
    auto e = c.error(req(MessageEntryType::FunctionCallReq, "unimplemented"));
    CHECK(e.type == MessageErrorType::InvalidOperation);
    CHECK(e.sub_name == "my_error");
    REQUIRE(e.param);
    auto param = f.unpack(*e.param, "varvalue");
    const auto* m = param.get_if<MapString>();
    REQUIRE(m);
    REQUIRE(m->find("param1"));
    CHECK(*m->find("param1")->as<std::int32_t>() == 10);
    CHECK(*m->find("param2")->as<std::string>() == "20");
}

TEST_CASE("functions: sync, async from another thread, structs, user and standard errors") {
    ServiceFixture f([](ServiceFixture& f) {
        REQUIRE(f.root->set_function("add", [](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            return Value::scalar<std::int32_t>(*a[0].as<std::int32_t>() + *a[1].as<std::int32_t>());
        }));
        REQUIRE(f.root->set_function("mid", [](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            auto x = (*a[0].field("x")->as<double>() + *a[1].field("x")->as<double>()) / 2;
            auto y = (*a[0].field("y")->as<double>() + *a[1].field("y")->as<double>()) / 2;
            return pt(x, y);
        }));
        auto* root = f.root.get();
        REQUIRE(f.root->set_function("fail_user", [root](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            return fail(root->user_error("Fault", *a[0].as<std::string>()));
        }));
        REQUIRE(f.root->set_async_function("later", [](const SessionRef&, std::vector<Value> a, Completion done) {
            std::thread([x = *a[0].as<double>(), done = std::move(done)] {
                std::this_thread::sleep_for(20ms);
                done(Value::scalar(x * 2));
                done(Value::scalar(0.0));  // a second completion is ignored
            }).detach();
        }));
    });
    auto c = f.connect();

    auto add = req(MessageEntryType::FunctionCallReq, "add");
    add.elements.push_back(make_scalar_element<std::int32_t>("a", 40));
    add.elements.push_back(make_scalar_element<std::int32_t>("b", 2));
    CHECK(scalar_of<std::int32_t>(c.ok(add), "return") == 42);

    auto mid = req(MessageEntryType::FunctionCallReq, "mid");
    mid.elements.push_back(f.pack(pt(0, 0), "Pt", "a"));
    mid.elements.push_back(f.pack(pt(2, 4), "Pt", "b"));
    auto r = c.ok(mid);
    CHECK(f.unpack(*r.find("return"), "Pt") == pt(1, 2));

    auto later = req(MessageEntryType::FunctionCallReq, "later");
    later.elements.push_back(make_scalar_element("x", 1.25));
    CHECK(scalar_of<double>(c.ok(later), "return") == 2.5);

    auto user = req(MessageEntryType::FunctionCallReq, "fail_user");
    user.elements.push_back(make_string_element("msg", "boom ü"));
    auto ur = c.call(user);
    REQUIRE(ur);
    CHECK(ur->error == MessageErrorType::RemoteError);
    CHECK(entry_error(*ur)->name == "example.objtest.Fault");
    CHECK(entry_error(*ur)->message == "boom ü");

    SECTION("argument errors") {
        auto missing = req(MessageEntryType::FunctionCallReq, "add");
        missing.elements.push_back(make_scalar_element<std::int32_t>("a", 1));
        auto e = c.error(missing);
        CHECK(e.type == MessageErrorType::MessageElementNotFound);
        CHECK(e.message == "Element b not found.");
        auto wrong = req(MessageEntryType::FunctionCallReq, "add");
        wrong.elements.push_back(make_scalar_element("a", 1.0));
        wrong.elements.push_back(make_scalar_element<std::int32_t>("b", 1));
        CHECK(c.error(wrong).type == MessageErrorType::DataTypeError);
        // a struct of another type where Pt is expected
        auto bad_struct = req(MessageEntryType::FunctionCallReq, "mid");
        MessageElement be = f.pack(pt(1, 1), "Pt", "a");
        be.type_name = "example.objtest.Other";
        bad_struct.elements.push_back(be);
        bad_struct.elements.push_back(f.pack(pt(1, 1), "Pt", "b"));
        CHECK(c.error(bad_struct).type == MessageErrorType::DataTypeError);
    }
    SECTION("not implemented, unknown member, unknown request type") {
        CHECK(c.error(req(MessageEntryType::FunctionCallReq, "unimplemented")).type == MessageErrorType::NotImplementedError);
        CHECK(c.error(req(MessageEntryType::FunctionCallReq, "nosuch")).type == MessageErrorType::MemberNotFound);
        auto odd = c.error(req(static_cast<MessageEntryType>(1179), "value"));
        CHECK(odd.type == MessageErrorType::ProtocolError);
        CHECK(odd.message == "Unknown request type");
        CHECK(f.root->set_function("count", {}).error().type == MessageErrorType::MemberNotFound);
        CHECK(f.root->set_generator_function("add", {}).error().type == MessageErrorType::MemberNotFound);
    }
    SECTION("a handler returning a value of the wrong type is answered with the packing error") {
        REQUIRE(f.root->set_function("add", [](const SessionRef&, std::vector<Value>) -> Result<Value> { return Value("x"); }));
        CHECK(c.error(add).type == MessageErrorType::DataTypeMismatch);
    }
}

TEST_CASE("events reach every client session, packed once, in order before the reply") {
    ServiceFixture f;
    auto* root = f.root.get();
    REQUIRE(f.root->set_function("unimplemented", [root](const SessionRef&, std::vector<Value>) -> Result<Value> {
        for (int i = 0; i < 3; ++i)
            if (auto r = root->fire_event("changed", {Value::scalar(double(i)), Value("why")}); !r) return r.take_error();
        return Value();
    }));
    auto a = f.connect();
    auto b = f.connect();
    std::vector<double> seen;
    std::mutex m;
    *a.hook = [&](MessageEntry& e) {
        if (e.entry_type != MessageEntryType::EventReq) return false;
        std::lock_guard lock(m);
        seen.push_back(scalar_of<double>(e, "v"));
        return true;
    };
    auto reply = a.ok(req(MessageEntryType::FunctionCallReq, "unimplemented"));
    CHECK(scalar_of<std::int32_t>(reply, "return") == 0);  // void: int32 0
    {
        std::lock_guard lock(m);
        CHECK(seen == std::vector<double>{0, 1, 2});  // all three arrived before the reply
    }
    for (int i = 0; i < 3; ++i) {
        auto ev = b.inbox->take(MessageEntryType::EventReq);
        REQUIRE(ev);
        CHECK(ev->service_path == "svc");
        CHECK(ev->member_name == "changed");
        CHECK(ev->request_id == 0);
        CHECK(scalar_of<double>(*ev, "v") == i);
        CHECK(read_string(*ev->find("why")) == "why");
    }
    CHECK(f.root->fire_event("changed", {Value::scalar(1.0)}).error().type == MessageErrorType::DataTypeError);
    CHECK(f.root->fire_event("changed", {Value("x"), Value("y")}).error().type == MessageErrorType::DataTypeMismatch);
    CHECK(f.root->fire_event("value", {}).error().type == MessageErrorType::MemberNotFound);
}

TEST_CASE("objrefs: resolution by index kind, types, nesting, caching and release") {
    std::shared_ptr<ServiceObject> sub, by_int_7, named, leaf;
    std::atomic<int> resolved{0};
    ServiceFixture f([&](ServiceFixture& f) {
        sub = ServiceObject::create(f.types, "example.objtest.Sub").value();
        by_int_7 = ServiceObject::create(f.types, "example.objtest.Sub").value();
        named = ServiceObject::create(f.types, "example.objtest.Sub").value();
        leaf = ServiceObject::create(f.types, "example.objtest.Sub").value();
        REQUIRE(sub->set_property_value("n", Value::scalar<std::int32_t>(1)));
        REQUIRE(by_int_7->set_property_value("n", Value::scalar<std::int32_t>(7)));
        REQUIRE(named->set_property_value("n", Value::scalar<std::int32_t>(3)));
        REQUIRE(f.root->set_objref("sub", [&](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
            CHECK(std::holds_alternative<std::monostate>(i));
            ++resolved;
            return sub;
        }));
        REQUIRE(f.root->set_objref("subs", [&](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
            if (std::get<std::int32_t>(i) == -7) return by_int_7;
            return fail(MessageErrorType::ObjectNotFound, "no subs[" + std::to_string(std::get<std::int32_t>(i)) + "]");
        }));
        REQUIRE(f.root->set_objref("named", [&](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
            if (std::get<std::string>(i) == "a b_c") return named;
            return fail(MessageErrorType::ObjectNotFound, "unknown");
        }));
        // `T[]` takes an int32 (as the official generated code); `T[]{string}` (accepted by the
        // official parser by mistake) the container's key.
        REQUIRE(f.root->set_objref("listed", [&](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
            if (std::get<std::int32_t>(i) == 7) return by_int_7;
            return fail(MessageErrorType::ObjectNotFound, "no listed[" + std::to_string(std::get<std::int32_t>(i)) + "]");
        }));
        REQUIRE(f.root->set_objref("listed_named", [&](const SessionRef&, const ObjRefIndex& i) -> Result<std::shared_ptr<ServiceObject>> {
            if (std::get<std::string>(i) == "a b_c") return named;
            return fail(MessageErrorType::ObjectNotFound, "unknown");
        }));
        REQUIRE(f.root->set_objref("anything", [&](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
            return f.root;  // varobject: any type
        }));
    });
    auto c = f.connect();
    auto type_of = [&](const std::string& path) { return c.call(req(MessageEntryType::ObjectTypeName, "", path)); };

    auto t = type_of("svc.sub");
    REQUIRE(t);
    CHECK(read_string(*t->find("objecttype")) == "example.objtest.Sub");
    CHECK(scalar_of<std::int32_t>(c.ok(req(MessageEntryType::PropertyGetReq, "n", "svc.sub")), "value") == 1);
    CHECK(resolved == 1);  // cached per path
    CHECK(sub->paths() == std::vector<std::string>{"svc.sub"});

    CHECK(scalar_of<std::int32_t>(c.ok(req(MessageEntryType::PropertyGetReq, "n", "svc.subs[%2d7]")), "value") == 7);
    CHECK(scalar_of<std::int32_t>(c.ok(req(MessageEntryType::PropertyGetReq, "n", "svc.named[a%20b%5fc]")), "value") == 3);
    CHECK(read_string(*type_of("svc.anything")->find("objecttype")) == "example.objtest.Thing");
    CHECK(scalar_of<std::int32_t>(c.ok(req(MessageEntryType::PropertyGetReq, "n", "svc.listed[7]")), "value") == 7);
    CHECK(scalar_of<std::int32_t>(c.ok(req(MessageEntryType::PropertyGetReq, "n", "svc.listed_named[a%20b%5fc]")), "value") == 3);

    SECTION("errors") {
        auto unknown = type_of("svc.subs[12]");
        REQUIRE(unknown);
        CHECK(unknown->error == MessageErrorType::ObjectNotFound);
        CHECK(entry_error(*unknown)->message == "no subs[12]");
        CHECK(type_of("svc.nosuch")->error == MessageErrorType::MemberNotFound);
        CHECK(type_of("svc.value")->error == MessageErrorType::MemberNotFound);  // a property, not an objref
        CHECK(type_of("svc.sub[1]")->error == MessageErrorType::ObjectNotFound);  // takes no index
        CHECK(type_of("svc.subs[x]")->error == MessageErrorType::ObjectNotFound); // int32 index expected
        CHECK(type_of("svc.subs")->error == MessageErrorType::ObjectNotFound);
        CHECK(type_of("svc.listed")->error == MessageErrorType::ObjectNotFound);     // index needed
        CHECK(type_of("svc.listed[x]")->error == MessageErrorType::ObjectNotFound);  // int32 index expected
        CHECK(type_of("other.sub")->error != MessageErrorType::None);
        CHECK(c.error(req(MessageEntryType::PropertyGetReq, "n", "svc.sub.deeper")).type == MessageErrorType::MemberNotFound);
        // an objref returning an object of the wrong type
        REQUIRE(f.root->set_objref("named", [&](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
            return f.root;
        }));
        CHECK(type_of("svc.named[zz]")->error == MessageErrorType::InternalError);
    }
    SECTION("release: clients get ServicePathReleasedReq, the path resolves again") {
        REQUIRE(f.service->release_path("svc.sub"));
        auto rel = c.inbox->take(MessageEntryType::ServicePathReleasedReq);
        REQUIRE(rel);
        CHECK(rel->service_path == "svc.sub");
        CHECK(sub->paths().empty());
        CHECK(f.service->release_path("svc.sub").error().type == MessageErrorType::ServiceError);
        CHECK(f.service->release_path("svc").error().type == MessageErrorType::InvalidArgument);
        CHECK(scalar_of<std::int32_t>(c.ok(req(MessageEntryType::PropertyGetReq, "n", "svc.sub")), "value") == 1);
        CHECK(resolved == 2);
    }
}

TEST_CASE("callbacks: call on a chosen client, return values and client errors") {
    ServiceFixture f;
    auto cb = f.root->callback("ask").value();
    auto tell = f.root->callback("tell").value();
    REQUIRE(f.root->set_async_function("call_back", [cb](const SessionRef& s, std::vector<Value> a, Completion done) {
        cb->call(s, {a[0]}, [done](Result<Value> r) {
            if (!r) return done(r.take_error());
            done(Value());
        });
    }));
    auto c = f.connect();
    std::weak_ptr<RawClient> weak = c.raw;
    *c.hook = [weak](MessageEntry& e) {
        if (e.entry_type != MessageEntryType::CallbackCallReq) return false;
        MessageEntry r;
        r.entry_type = MessageEntryType::CallbackCallRet;
        r.service_path = e.service_path;
        r.member_name = e.member_name;
        r.request_id = e.request_id;
        if (e.member_name == "ask") {
            double x = 0;
            read_scalar(*e.find("x"), x);
            if (x < 0)
                set_entry_error(r, make_error(MessageErrorType::InvalidArgument, "negative"));
            else
                r.elements.push_back(make_scalar_element("return", x * 3));
        } else {
            r.elements.push_back(make_scalar_element<std::int32_t>("return", 0));
        }
        if (auto cl = weak.lock()) cl->send(std::move(r));
        return true;
    };
    auto session = f.service->sessions().at(0);

    std::promise<Result<Value>> p;
    cb->call(session, {Value::scalar(2.0)}, [&](Result<Value> r) { p.set_value(std::move(r)); });
    auto r = p.get_future().get();
    REQUIRE(r);
    CHECK(*r->as<double>() == 6.0);

    std::promise<Result<Value>> p2;
    cb->call(session, {Value::scalar(-1.0)}, [&](Result<Value> r) { p2.set_value(std::move(r)); });
    auto r2 = p2.get_future().get();
    REQUIRE_FALSE(r2);
    CHECK(r2.error().type == MessageErrorType::InvalidArgument);
    CHECK(r2.error().message == "negative");

    std::promise<Result<Value>> p3;
    tell->call(session, {Value("hi")}, [&](Result<Value> r) { p3.set_value(std::move(r)); });
    auto r3 = p3.get_future().get();
    REQUIRE(r3);
    CHECK(r3->is_null());

    std::promise<Result<Value>> p4;
    cb->call(session, {}, [&](Result<Value> r) { p4.set_value(std::move(r)); });
    CHECK(p4.get_future().get().error().type == MessageErrorType::DataTypeError);

    // from a function handler: the callback completes before the function's reply
    auto call = req(MessageEntryType::FunctionCallReq, "call_back");
    call.elements.push_back(make_scalar_element("x", 1.0));
    c.ok(call);
    call.elements[0] = make_scalar_element("x", -1.0);
    CHECK(c.error(call).type == MessageErrorType::InvalidArgument);
}

TEST_CASE("authentication: password table, login at connect, refused logins") {
    PasswordTable users;
    users.add_user("alice", "secret");
    REQUIRE(users.add_user_md5("bob", "5F4DCC3B5AA765D61D8327DEB882CF99"));  // "password"
    CHECK(PasswordTable::md5_hex("password") == "5f4dcc3b5aa765d61d8327deb882cf99");
    CHECK_FALSE(users.add_user_md5("eve", "xyz"));
    auto parsed = PasswordTable::parse("# users\ncarol 5f4dcc3b5aa765d61d8327deb882cf99 objectlock,other\n\ndave 5f4dcc3b5aa765d61d8327deb882cf99 _\n");
    REQUIRE(parsed);
    REQUIRE(parsed->users().size() == 2);
    CHECK(parsed->users()[0].privileges == std::vector<std::string>{"objectlock", "other"});
    CHECK(parsed->users()[1].privileges.empty());
    CHECK_FALSE(PasswordTable::parse("onlyname\n"));

    ServiceFixture f([](ServiceFixture& f) { REQUIRE(f.root->set_property_value("value", Value::scalar(4.0))); });
    f.service->set_users(users);
    CHECK(f.service->requires_authentication());

    RawClientOptions none;
    auto refused = f.try_connect(none);
    REQUIRE_FALSE(refused);
    CHECK(refused.error().type == MessageErrorType::AuthenticationError);

    RawClientOptions wrong;
    wrong.username = "alice";
    wrong.password = "nope";
    auto w = f.try_connect(wrong);
    REQUIRE_FALSE(w);
    CHECK(w.error().type == MessageErrorType::AuthenticationError);

    RawClientOptions good;
    good.username = "bob";
    good.password = "password";
    auto c = f.connect(good);
    CHECK(scalar_of<double>(c.ok(req(MessageEntryType::PropertyGetReq, "value")), "value") == 4.0);
    REQUIRE(f.service->sessions().size() == 1);
    CHECK(f.service->sessions()[0].username() == "bob");
}
