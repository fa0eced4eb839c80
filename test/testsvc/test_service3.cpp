// TestService3.testroot3 and its objects (obj4, obj5): RobotRaconteurTestService2.
#include <map>
#include <mutex>

#include "core/value/pack_value.hpp"
#include "robdef/parser.hpp"
#include "server/service/memory_member.hpp"
#include "server/service/pipe_member.hpp"
#include "server/service/wire_member.hpp"
#include "test/testsvc/test_services.hpp"

namespace rr::testsvc {

using namespace rr::server;

namespace {

constexpr std::int32_t kPeekwireValue = 56295674;  // what the official service keeps on peekwire

/// A generator of a fixed list of values (then StopIteration).
class ListGenerator : public Generator {
public:
    explicit ListGenerator(std::vector<Value> items) : items_(std::move(items)) {}
    Result<Value> next(std::optional<Value>) override {
        if (aborted_) return fail(MessageErrorType::OperationAborted, "generator aborted");
        if (i_ >= items_.size()) return fail(MessageErrorType::StopIteration, "");
        return items_[i_++];
    }
    Result<void> close() override {
        i_ = items_.size();
        return {};
    }
    Result<void> abort() override {
        aborted_ = true;
        return {};
    }

private:
    std::vector<Value> items_;
    std::size_t i_ = 0;
    bool aborted_ = false;
};

/// gen_func4: the official behaviour: each uint8[] sent comes back with the call's count (0, 1, …)
/// added to every byte, for 8 calls; then StopIteration. Close makes the next call StopIteration,
/// abort OperationAborted.
class AddCountGenerator : public Generator {
public:
    Result<Value> next(std::optional<Value> p) override {
        if (aborted_) return fail(MessageErrorType::OperationAborted, "generator aborted");
        if (j_ >= 8) return fail(MessageErrorType::StopIteration, "");
        const auto* a = p ? p->get_if<NumericArray>() : nullptr;
        if (!a || a->type() != DataTypes::uint8_t) return fail(MessageErrorType::InvalidArgument, "uint8[] expected");
        std::vector<std::uint8_t> out(a->size());
        auto in = a->view<std::uint8_t>();
        for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<std::uint8_t>(in[i] + j_);
        ++j_;
        return Value(NumericArray::adopt<std::uint8_t>(std::move(out)));
    }
    Result<void> close() override {
        j_ = 1000;
        return {};
    }
    Result<void> abort() override {
        aborted_ = true;
        return {};
    }

private:
    std::uint32_t j_ = 0;
    bool aborted_ = false;
};

/// A parameter generator that gives back what it receives (gen_func3 with a void return, gen_func5,
/// enum_generator2). Ends normally on close.
class EchoGenerator : public Generator {
public:
    explicit EchoGenerator(bool void_return) : void_return_(void_return) {}
    Result<Value> next(std::optional<Value> p) override {
        if (aborted_) return fail(MessageErrorType::OperationAborted, "generator aborted");
        if (closed_) return fail(MessageErrorType::StopIteration, "");
        if (!p) return fail(MessageErrorType::InvalidArgument, "a value is expected");
        return void_return_ ? Value() : std::move(*p);
    }
    Result<void> close() override {
        closed_ = true;
        return {};
    }
    Result<void> abort() override {
        aborted_ = true;
        return {};
    }

private:
    bool void_return_;
    bool closed_ = false, aborted_ = false;
};

Value exception_params(std::int32_t p1, const std::string& p2) {
    MapString m;
    m.entries.emplace_back("param1", Value::scalar<std::int32_t>(p1));
    m.entries.emplace_back("param2", Value(p2));
    return Value(std::move(m));
}

}  // namespace

struct TestRoot3::State {
    Context c;
    std::unique_ptr<Ts3Values> ts3;
    std::shared_ptr<ServiceObject> root, obj5;
    std::shared_ptr<void> obj4;  // the holder of the obj4 object (its o3_1 objects)
    std::shared_ptr<ServiceObject> obj4_object;
    std::shared_ptr<WireMember> peekwire;

    void build();
    RRError error_with_params(RRError e, std::string sub_name, Value params) const {
        e.sub_name = std::move(sub_name);
        auto t = robdef::parse_type("varvalue");
        auto packed = pack_value(params, *t, "errorparam", c.types->set(), {});
        if (packed) e.param = std::make_shared<const MessageElement>(std::move(*packed));
        return e;
    }
};

std::shared_ptr<void> make_obj4_holder(const Context& c, std::shared_ptr<ServiceObject>& object);

void TestRoot3::State::build() {
    ts3 = std::make_unique<Ts3Values>(c.values->sequence());
    root = make_object(c, kTs3 + ".testroot3");
    serve_table_properties(c, *root,
                           {"testenum1_prop", "testpod1_prop", "teststruct3_prop", "testnamedarray1", "testnamedarray2",
                            "testnamedarray3", "testnamedarray4", "testnamedarray5"});
    State* self = this;

    // properties with recipes (sequence_gen.hpp): get one value, expect another on set
    auto recipe = [&](const char* name, Value get, Value expected) {
        auto g = std::make_shared<const Value>(std::move(get));
        auto e = std::make_shared<const Value>(std::move(expected));
        std::string what = std::string("property ") + name;
        must(root->set_property_handlers(
                 name, [g](const SessionRef&) -> Result<Value> { return *g; },
                 [e, what](const SessionRef&, Value v) -> Result<void> { return expect_value(v, *e, what); }),
             what);
    };
    const std::string enum_type = kTs3 + ".testenum1";
    recipe("testenum1_prop", Value(Enum{enum_type, -1}), Value(Enum{enum_type, 0x10}));  // anothervalue; hexval1
    recipe("testpod1_prop", ts3->testpod1(563921043), ts3->testpod1(85932659));
    recipe("teststruct3_prop", ts3->teststruct3(16483675), ts3->teststruct3(858362));
    recipe("testnamedarray1", ts3->vector3_of_transform(74637), ts3->vector3_of_transform(3956378));
    recipe("testnamedarray2", ts3->transform(1294), ts3->transform(827635));
    recipe("testnamedarray3", ts3->transform_array(8, 837512), ts3->transform_array(6, 19274));
    recipe("testnamedarray4", ts3->transform_multidim(7, 2, 66134), ts3->transform_multidim(5, 2, 6385));
    recipe("testnamedarray5", ts3->transform_multidim(3, 2, 773142), ts3->transform_multidim(3, 2, 7732));

    auto fn = [&](const char* name, FunctionHandler h) { must(root->set_function(name, std::move(h)), name); };
    {
        auto expected = std::make_shared<const Value>(ts3->testpod1(29546592));
        fn("testpod1_func1", [expected](const SessionRef&, std::vector<Value> a) -> Result<Value> {
            if (auto r = expect_value(a[0], *expected, "testpod1_func1 s"); !r) return r.take_error();
            return Value();
        });
        auto ret = std::make_shared<const Value>(ts3->testpod1(95836295));
        fn("testpod1_func2", [ret](const SessionRef&, std::vector<Value>) -> Result<Value> { return *ret; });
    }
    fn("test_exception_params1", [self](const SessionRef&, std::vector<Value>) -> Result<Value> {
        return fail(self->error_with_params(make_error(MessageErrorType::InvalidOperation, "test error"), "my_error",
                                            exception_params(10, "20")));
    });
    fn("test_exception_params2", [self](const SessionRef&, std::vector<Value>) -> Result<Value> {
        return fail(self->error_with_params(self->root->user_error("test_exception4", "test error2"), "my_error2",
                                            exception_params(30, "40")));
    });

    // generators
    auto gen = [&](const char* name, GeneratorFunctionHandler h) { must(root->set_generator_function(name, std::move(h)), name); };
    gen("gen_func1", [](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
        std::vector<Value> items;
        for (int i = 0; i < 16; ++i) items.push_back(Value::scalar<double>(i));
        return std::shared_ptr<Generator>(std::make_shared<ListGenerator>(std::move(items)));
    });
    gen("gen_func2", [](const SessionRef&, std::vector<Value> a) -> Result<std::shared_ptr<Generator>> {
        auto name = a[0].as<std::string>();
        if (!name || *name != "gen_func2_a_param")
            return fail(MessageErrorType::InvalidArgument, "gen_func2: name must be \"gen_func2_a_param\"");
        std::vector<Value> items;
        for (int i = 0; i < 16; ++i) items.push_back(Value(NumericArray::from<std::uint8_t>({static_cast<std::uint8_t>(i)})));
        return std::shared_ptr<Generator>(std::make_shared<ListGenerator>(std::move(items)));
    });
    gen("gen_func3", [](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
        return std::shared_ptr<Generator>(std::make_shared<EchoGenerator>(true));
    });
    gen("gen_func4", [](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
        return std::shared_ptr<Generator>(std::make_shared<AddCountGenerator>());
    });
    gen("gen_func5", [](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
        return std::shared_ptr<Generator>(std::make_shared<EchoGenerator>(false));
    });
    gen("enum_generator1", [self, enum_type](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
        std::vector<Value> items;
        const auto* svc = self->c.types->set().find(enum_type).enumeration;
        if (svc)
            for (const auto& v : svc->values) items.push_back(Value(Enum{enum_type, v.value}));
        return std::shared_ptr<Generator>(std::make_shared<ListGenerator>(std::move(items)));
    });
    gen("enum_generator2", [](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
        return std::shared_ptr<Generator>(std::make_shared<EchoGenerator>(false));
    });

    // objrefs
    obj4 = make_obj4_holder(c, obj4_object);
    must(root->set_objref("o4", [self](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
             return self->obj4_object;
         }),
         "o4");
    obj5 = make_object(c, kTs3 + ".obj5");
    for (const char* p : {"p1", "p2", "p3"}) must(obj5->set_property_value(p, Value::scalar<double>(0)), p);
    must(obj5->set_function("f1", [](const SessionRef&, std::vector<Value>) -> Result<Value> { return Value::scalar<std::int32_t>(10); }), "f1");
    must(obj5->set_function("f2", [](const SessionRef&, std::vector<Value>) -> Result<Value> { return Value::scalar<std::int32_t>(11); }), "f2");
    for (const char* w : {"w1", "w2"}) must(must(obj5->wire(w), w)->set_out_value(Value::scalar<std::int32_t>(0)), w);
    for (const char* m : {"m1", "m2", "m3"}) must(must(obj5->memory(m), m)->set_contents(zero_numbers(DataTypes::int32_t, 100)), m);
    must(root->set_objref("nolock_test", [self](const SessionRef&, const ObjRefIndex&) -> Result<std::shared_ptr<ServiceObject>> {
             return self->obj5;
         }),
         "nolock_test");

    // pipes and wires: a client's packet comes back to it
    for (const char* name : {"p1", "p2", "p3"})
        must(root->pipe(name), name)->on_packet([](const std::shared_ptr<PipeEndpoint>& ep, Value v) { (void)ep->send(v); });
    for (const char* name : {"w1", "w2", "w3"})
        must(root->wire(name), name)->on_value([](const std::shared_ptr<WireConnection>& conn, const Value& v, TimeSpec) {
            if (conn) (void)conn->set_out_value(v);
        });
    peekwire = must(root->wire("peekwire"), "peekwire");
    must(peekwire->set_out_value(Value::scalar<std::int32_t>(kPeekwireValue)), "peekwire");

    // memories
    auto mem = [&](const char* name, Value contents) { must(must(root->memory(name), name)->set_contents(std::move(contents)), name); };
    mem("readmem", must(c.values->lfsr("double[100]", "readmem_init"), "readmem"));
    mem("pod_m1", zero_pods(c, kTs3 + ".testpod2", 1024));
    mem("pod_m2", zero_pods(c, kTs3 + ".testpod2", 9, {3, 3}));
    mem("namedarray_m1", zero_namedarrays(c, kTs3 + ".transform", 512));
    mem("namedarray_m2", zero_namedarrays(c, kTs3 + ".transform", 100, {10, 10}));
    mem("c_m1", zero_numbers(DataTypes::cdouble_t, 100));
    mem("c_m2", zero_numbers(DataTypes::cdouble_t, 9, {3, 3}));
    mem("c_m3", zero_numbers(DataTypes::cdouble_t, 100));
    mem("c_m4", zero_numbers(DataTypes::cdouble_t, 9, {3, 3}));
    mem("c_m5", zero_numbers(DataTypes::bool_t, 512));
    mem("c_m6", zero_numbers(DataTypes::bool_t, 100, {10, 10}));
}

TestRoot3::TestRoot3(std::unique_ptr<State> state) : s_(std::move(state)) {}
TestRoot3::~TestRoot3() = default;

std::shared_ptr<TestRoot3> TestRoot3::create(const Context& c) {
    auto s = std::make_unique<State>();
    s->c = c;
    s->build();
    return std::shared_ptr<TestRoot3>(new TestRoot3(std::move(s)));
}

const std::shared_ptr<ServiceObject>& TestRoot3::root() const { return s_->root; }

void TestRoot3::attach(const std::shared_ptr<ObjectService>& service) {
    must(service->request_object_lock(service->name() + ".nolock_test", "server"), "lock nolock_test");
}

}  // namespace rr::testsvc
