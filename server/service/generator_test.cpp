// Generator functions at the entry level: index, Next with and without parameter, StopIteration,
// close (request with Error 109), abort (Error 107), and requests after the end.
#include "server/service/object_service_fixture.hpp"
#include "test/support/eventually.hpp"

#include <thread>

using namespace rr;
using namespace rr::server;
using namespace rr::server::testing;

namespace {

struct Log {
    std::mutex m;
    std::vector<std::string> lines;
    void add(std::string s) {
        std::lock_guard lock(m);
        lines.push_back(std::move(s));
    }
    std::vector<std::string> get() {
        std::lock_guard lock(m);
        return lines;
    }
};

MessageEntry next(const char* member, std::int32_t index, MessageErrorType error = MessageErrorType::None) {
    auto e = req(MessageEntryType::GeneratorNextReq, member);
    if (error != MessageErrorType::None)
        set_entry_error(e, make_error(error, error == MessageErrorType::StopIteration ? "" : "Generator abort requested"));
    e.elements.push_back(make_scalar_element<std::int32_t>("index", index));
    return e;
}

}  // namespace

TEST_CASE("generators: return generator to the end, close, abort, and requests after the end") {
    auto log = std::make_shared<Log>();
    ServiceFixture f([log](ServiceFixture& f) {
        REQUIRE(f.root->set_generator_function(
            "count", [log](const SessionRef&, std::vector<Value> a) -> Result<std::shared_ptr<Generator>> {
                auto i = std::make_shared<std::int32_t>(0);
                const std::int32_t n = *a[0].as<std::int32_t>();
                return std::shared_ptr<Generator>(std::make_shared<FunctionGenerator>(
                    [i, n](std::optional<Value> p) -> Result<Value> {
                        CHECK_FALSE(p);
                        if (*i >= n) return fail(MessageErrorType::StopIteration, "done");
                        return Value::scalar<std::int32_t>((*i)++);
                    },
                    [log]() -> Result<void> {
                        log->add("close");
                        return {};
                    },
                    [log]() -> Result<void> {
                        log->add("abort");
                        return {};
                    }));
            }));
    });
    auto c = f.connect();
    auto start = [&](std::int32_t n) {
        auto call = req(MessageEntryType::FunctionCallReq, "count");
        call.elements.push_back(make_scalar_element<std::int32_t>("n", n));
        auto r = c.ok(call);
        auto index = scalar_of<std::int32_t>(r, "index");
        CHECK(index >= 0);
        return index;
    };

    const auto g = start(2);
    CHECK(scalar_of<std::int32_t>(c.ok(next("count", g)), "return") == 0);
    CHECK(scalar_of<std::int32_t>(c.ok(next("count", g)), "return") == 1);
    auto end = c.error(next("count", g));
    CHECK(end.type == MessageErrorType::StopIteration);
    CHECK(end.name == "RobotRaconteur.StopIteration");
    // the index is gone after the end
    auto after = c.error(next("count", g));
    CHECK(after.type == MessageErrorType::InvalidOperation);
    CHECK(after.message == "Invalid generator");

    SECTION("close: request with Error 109, answered with return int32 0; the next Next StopIteration, then the index is gone") {
        const auto h = start(10);
        CHECK(scalar_of<std::int32_t>(c.ok(next("count", h)), "return") == 0);
        CHECK(scalar_of<std::int32_t>(c.ok(next("count", h, MessageErrorType::StopIteration)), "return") == 0);
        CHECK(log->get() == std::vector<std::string>{"close"});
        CHECK(c.error(next("count", h)).type == MessageErrorType::StopIteration);  // as official clients expect
        CHECK(c.error(next("count", h)).type == MessageErrorType::InvalidOperation);
    }
    SECTION("abort: request with Error 107; the next Next OperationAborted, then the index is gone") {
        const auto h = start(10);
        CHECK(scalar_of<std::int32_t>(c.ok(next("count", h, MessageErrorType::AbortOperation)), "return") == 0);
        CHECK(log->get() == std::vector<std::string>{"abort"});
        CHECK(c.error(next("count", h)).type == MessageErrorType::OperationAborted);
        CHECK(c.error(next("count", h)).type == MessageErrorType::InvalidOperation);
    }
    SECTION("wrong index, wrong member, missing index, another client's generator") {
        const auto h = start(10);
        CHECK(c.error(next("count", h + 1)).type == MessageErrorType::InvalidOperation);
        CHECK(c.error(next("sum", h)).type == MessageErrorType::InvalidOperation);
        CHECK(c.error(req(MessageEntryType::GeneratorNextReq, "count")).type == MessageErrorType::MessageElementNotFound);
        auto other = f.connect();
        CHECK(other.error(next("count", h)).type == MessageErrorType::InvalidOperation);
        CHECK(scalar_of<std::int32_t>(c.ok(next("count", h)), "return") == 0);  // still the owner's
    }
    SECTION("a generator function without a handler") {
        CHECK(c.error(req(MessageEntryType::FunctionCallReq, "sum")).type == MessageErrorType::NotImplementedError);
    }
}

TEST_CASE("generators: parameter generators, with and without a return value") {
    auto collected = std::make_shared<std::vector<std::string>>();
    ServiceFixture f([collected](ServiceFixture& f) {
        REQUIRE(f.root->set_generator_function("sum", [](const SessionRef&, std::vector<Value> a) -> Result<std::shared_ptr<Generator>> {
            CHECK(a.empty());  // the {generator} parameter is not a call argument
            auto total = std::make_shared<double>(0);
            return std::shared_ptr<Generator>(std::make_shared<FunctionGenerator>([total](std::optional<Value> p) -> Result<Value> {
                REQUIRE(p);
                *total += *p->as<double>();
                return Value::scalar(*total);
            }));
        }));
        REQUIRE(f.root->set_generator_function("sink", [collected](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
            return std::shared_ptr<Generator>(std::make_shared<FunctionGenerator>([collected](std::optional<Value> p) -> Result<Value> {
                collected->push_back(*p->as<std::string>());
                return Value();
            }));
        }));
    });
    auto c = f.connect();
    const auto g = scalar_of<std::int32_t>(c.ok(req(MessageEntryType::FunctionCallReq, "sum")), "index");
    for (double x : {1.0, 2.5, -0.5}) {
        auto n = next("sum", g);
        n.elements.push_back(make_scalar_element("parameter", x));
        c.ok(n);
    }
    auto n = next("sum", g);
    n.elements.push_back(make_scalar_element("parameter", 10.0));
    CHECK(scalar_of<double>(c.ok(n), "return") == 13.0);
    CHECK(c.error(next("sum", g)).type == MessageErrorType::MessageElementNotFound);  // no parameter
    auto bad = next("sum", g);
    bad.elements.push_back(make_string_element("parameter", "x"));
    CHECK(c.error(bad).type == MessageErrorType::DataTypeError);
    CHECK(scalar_of<std::int32_t>(c.ok(next("sum", g, MessageErrorType::StopIteration)), "return") == 0);

    const auto s = scalar_of<std::int32_t>(c.ok(req(MessageEntryType::FunctionCallReq, "sink")), "index");
    auto one = next("sink", s);
    one.elements.push_back(make_string_element("parameter", "a"));
    CHECK(scalar_of<std::int32_t>(c.ok(one), "return") == 0);  // void: int32 0
    CHECK(*collected == std::vector<std::string>{"a"});
}

TEST_CASE("generators: dropped when their session ends") {
    std::atomic<int> alive{0};
    struct Counted : Generator {
        std::atomic<int>* n;
        explicit Counted(std::atomic<int>* c) : n(c) { ++*n; }
        ~Counted() override { --*n; }
    };
    ServiceFixture f([&](ServiceFixture& f) {
        REQUIRE(f.root->set_generator_function("count", [&](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
            return std::shared_ptr<Generator>(std::make_shared<Counted>(&alive));
        }));
    });
    {
        auto c = f.connect();
        auto call = req(MessageEntryType::FunctionCallReq, "count");
        call.elements.push_back(make_scalar_element<std::int32_t>("n", 1));
        for (int i = 0; i < 3; ++i) c.ok(call);
        CHECK(alive == 3);
        // a generator with no more values answers StopIteration by default
        auto g = scalar_of<std::int32_t>(c.ok(call), "index");
        CHECK(c.error(next("count", g)).type == MessageErrorType::StopIteration);
        c.raw->close();
    }
    CHECK(rr::testing::eventually([&] { return alive == 0; }));
}
