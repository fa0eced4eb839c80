// LFSR values (value_fill.hpp) and the TestService3 recipes (sequence_gen.hpp) against the official
// test definitions: every property type of every test object gets a value that packs as its type and
// unpacks to the same value; the same key draws the same value, another key another one.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "core/value/pack_value.hpp"
#include "server/service/service_types.hpp"
#include "test/support/skip.hpp"
#include "test/testsvc/sequence_gen.hpp"
#include "test/testsvc/test_values.hpp"
#include "test/testsvc/value_fill.hpp"

using namespace rr;
using namespace rr::testsvc;

namespace {

std::shared_ptr<const server::ServiceTypes> testing_types() {
    auto dir = rr::test::shared_dir() / "robdef-testing";
    std::vector<std::string> texts;
    for (int n : {1, 2, 3, 4, 5}) {
        std::ifstream in(dir / ("com.robotraconteur.testing.TestService" + std::to_string(n) + ".robdef"));
        if (!in) return nullptr;
        std::ostringstream s;
        s << in.rdbuf();
        texts.push_back(s.str());
    }
    auto t = server::ServiceTypes::create(std::move(texts));
    REQUIRE(t);
    return *t;
}

void round_trip(const server::ServiceTypes& types, const Value& v, const robdef::TypeDefinition& type,
                const std::string& svc, const std::string& what) {
    INFO(what);
    auto e = pack_value(v, type, "value", types.set(), svc);
    INFO((e ? std::string() : e.error().message));
    REQUIRE(e);
    auto back = unpack_value(*e, type, types.set(), svc);
    INFO((back ? std::string() : back.error().message));
    REQUIRE(back);
    CHECK(same_value(*back, v));
}

}  // namespace

TEST_CASE("testsvc values: every property of the test objects gets an LFSR value of its type", "[shared]") {
    auto types = testing_types();
    if (!types) RR_SKIP("no " + (rr::test::shared_dir() / "robdef-testing").string());
    std::size_t checked = 0;
    for (const char* object : {"com.robotraconteur.testing.TestService1.testroot", "com.robotraconteur.testing.TestService3.testroot3",
                               "com.robotraconteur.testing.TestService5.asynctestroot"}) {
        const auto* def = types->find_object(object);
        REQUIRE(def);
        const std::string svc = std::string(object).substr(0, std::string(object).rfind('.'));
        for (const auto& m : def->members) {
            if (m.kind != robdef::MemberKind::property) continue;
            Lfsr a(55, m.name + "_get"), b(55, m.name + "_get"), other(55, m.name + "_set");
            auto va = lfsr_value(m.type, a, types->set(), svc);
            INFO(object << "." << m.name << ": " << (va ? std::string() : va.error().message));
            REQUIRE(va);
            auto vb = lfsr_value(m.type, b, types->set(), svc);
            REQUIRE(vb);
            CHECK(same_value(*va, *vb));
            CHECK(a.state() == b.state());  // the same numbers drawn
            CHECK(a.state() != other.state());
            round_trip(*types, *va, m.type, svc, std::string(object) + "." + m.name);
            ++checked;
        }
    }
    CHECK(checked >= 90);  // 97 in the definitions of commit 018ccf2
}

TEST_CASE("testsvc values: same_value takes NaN as NaN, maps in any order, and tells other values apart") {
    const double nan1 = std::numeric_limits<double>::quiet_NaN();
    CHECK(same_value(Value::scalar(nan1), Value::scalar(-nan1)));
    CHECK(same_value(Value::scalar(0.0), Value::scalar(-0.0)));
    CHECK_FALSE(same_value(Value::scalar(1.0), Value::scalar(nan1)));
    CHECK_FALSE(same_value(Value::scalar(1.0), Value::scalar(1.0f)));  // another numeric type
    MapInt32 m1{{{1, Value("a")}, {2, Value("b")}}}, m2{{{2, Value("b")}, {1, Value("a")}}}, m3{{{1, Value("a")}}};
    CHECK(same_value(Value(m1), Value(m2)));
    CHECK_FALSE(same_value(Value(m1), Value(m3)));
    CHECK_FALSE(same_value(Value(List{{Value("a")}}), Value(List{{Value("b")}})));
    CHECK_FALSE(same_value(Value(), Value("")));
}

TEST_CASE("testsvc values: an LFSR stuck at zero draws zeros and the shortest lengths") {
    Lfsr zero = Lfsr::from_state(0);
    CHECK(zero.next_double() == 0.0);
    CHECK(zero.next_len(16) == 0);
    CHECK(zero.next_dist(1, 3) == 1);
    CHECK(zero.state() == 0u);
}

TEST_CASE("testsvc recipes: TestService3 values pack as their types, and seeds tell them apart", "[shared]") {
    auto types = testing_types();
    if (!types) RR_SKIP("no " + (rr::test::shared_dir() / "robdef-testing").string());
    const auto tables = SequenceTables::lfsr(55);
    CHECK(tables.doubles.size() == 7919);
    CHECK(tables.uint32s.size() == 7727);
    for (double d : tables.doubles) REQUIRE((d >= 0.0 && d < 1.0));
    Ts3Values ts3(tables);
    const std::string svc = "com.robotraconteur.testing.TestService3";
    const auto* root = types->find_object(svc + ".testroot3");
    REQUIRE(root);
    auto type_of = [&](const char* member) { return root->find_member(member)->type; };
    round_trip(*types, ts3.testpod1(563921043), type_of("testpod1_prop"), svc, "testpod1");
    round_trip(*types, ts3.teststruct3(858362), type_of("teststruct3_prop"), svc, "teststruct3");
    round_trip(*types, ts3.vector3_of_transform(74637), type_of("testnamedarray1"), svc, "vector3");
    round_trip(*types, ts3.transform(1294), type_of("testnamedarray2"), svc, "transform");
    round_trip(*types, ts3.transform_array(8, 837512), type_of("testnamedarray3"), svc, "transform[10-]");
    round_trip(*types, ts3.transform_multidim(7, 2, 66134), type_of("testnamedarray4"), svc, "transform[*]");
    round_trip(*types, ts3.transform_multidim(3, 2, 773142), type_of("testnamedarray5"), svc, "transform[3,2]");
    CHECK(same_value(ts3.testpod1(563921043), ts3.testpod1(563921043)));
    CHECK_FALSE(same_value(ts3.testpod1(563921043), ts3.testpod1(85932659)));
    CHECK_FALSE(same_value(ts3.teststruct3(858362), ts3.teststruct3(16483675)));

    // The counter walk: seed 100 starts at 100 and steps 100 mod 17 + 7 = 22.
    SequenceGen g(tables, 100);
    CHECK(g.next_double() == tables.doubles[122]);
    CHECK(g.next_uint32() == tables.uint32s[144]);
    CHECK(g.next_int8() == 166 - 128);
    SequenceGen far(tables, 7823 + 100);  // the same start, another step: 7923 mod 17 + 7 = 8
    CHECK(far.next_double() == tables.doubles[108]);
}

TEST_CASE("testsvc values: an official values file replaces the values it names, and bad files are refused", "[shared]") {
    auto types = testing_types();
    if (!types) RR_SKIP("no " + (rr::test::shared_dir() / "robdef-testing").string());
    const auto dir = std::filesystem::temp_directory_path() / ("testsvc-values-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(dir / name) << text;
        return (dir / name).string();
    };
    const std::string root = "com.robotraconteur.testing.TestService1.testroot";
    const auto good = write("good.json", R"({"format": "rr-testsvc-official-values 1", "objects": {
        "com.robotraconteur.testing.TestService1.testroot": {
            "properties": {"d1": {"get": 12.5, "set": 3.25}, "str1": {"get": "hello"}},
            "memories": {"m1": [1.0, 2.0]}}},
        "sequence": {"doubles": [0.5, 0.25], "uint32s": [7, 9, 11]}})");
    auto v = TestValues::load_official(types, good);
    INFO((v ? std::string() : v.error().message));
    REQUIRE(v);
    CHECK(v->official());
    CHECK(same_value(*v->get(root, "d1"), Value::scalar(12.5)));
    CHECK(same_value(**v->expected_set(root, "d1"), Value::scalar(3.25)));
    CHECK(same_value(*v->get(root, "str1"), Value("hello")));
    CHECK_FALSE(v->expected_set(root, "str1")->has_value());  // named without a set value: any value
    Lfsr g(TestValues::kSeed, "d2_get");  // not named: the LFSR value
    CHECK(same_value(*v->get(root, "d2"), *lfsr_value(types->find_object(root)->find_member("d2")->type, g, types->set(),
                                                      "com.robotraconteur.testing.TestService1")));
    REQUIRE(v->memory(root, "m1"));
    CHECK(v->memory(root, "m1")->get_if<NumericArray>()->size() == 2);
    CHECK(v->sequence().uint32s.size() == 3);
    CHECK(v->get(root, "nosuch").error().type == MessageErrorType::MemberNotFound);

    for (const char* text : {R"({"format": "other"})", R"(not json)",
                             R"({"format": "rr-testsvc-official-values 1", "objects": {"x.y.z": {}}})",
                             R"({"format": "rr-testsvc-official-values 1", "objects": {"com.robotraconteur.testing.TestService1.testroot": {"properties": {"func1": {"get": 1}}}}})",
                             R"({"format": "rr-testsvc-official-values 1", "objects": {"com.robotraconteur.testing.TestService1.testroot": {"properties": {"d1": {"get": "text"}}}}})",
                             R"({"format": "rr-testsvc-official-values 1", "sequence": {"doubles": [], "uint32s": [1]}})"}) {
        INFO(text);
        auto bad = TestValues::load_official(types, write("bad.json", text));
        REQUIRE_FALSE(bad);
        CHECK(bad.error().type == MessageErrorType::InvalidArgument);
        CHECK(bad.error().message.find("bad.json") != std::string::npos);
    }
    CHECK(TestValues::load_official(types, (dir / "missing.json").string()).error().type == MessageErrorType::IOError);
    std::filesystem::remove_all(dir);
}
