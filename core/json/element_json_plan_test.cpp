// The compiled element → JSON text plan gives exactly the general path's text (unpack_value →
// value_to_json → nlohmann dump) for every type it covers, declines what it does not cover, and
// never renders an element the general path refuses: checked on hand-written values of every kind
// and on thousands of randomly broken element trees.
#include <catch2/catch.hpp>

#include <random>

#include "core/json/element_json_plan.hpp"
#include "core/json/value_json.hpp"
#include "core/value/element_layout.hpp"
#include "core/value/test_values.hpp"

using namespace rr;
using namespace rr::testing;
using element_json_text::Plan;

namespace {

constexpr std::string_view kPlanRobdef = R"(service example.plan
stdver 0.10
import example.test

enum Mode
    idle = 0,
    run = 3
end

struct State
    field uint64 seqno
    field Mode mode
    field example.test.Color color
    field string name
    field double[] q
    field example.test.Pose[] tcp
    field example.test.Vec3 v
    field example.test.Sample sample
    field example.test.Packet[] packets
    field example.test.Inner{list} inners
    field double[]{int32} by_id
    field string{string} labels
    field int32[*] grid
    field uint8[2,3] fixed
    field State next
    field example.test.Inner maybe
    field cdouble c
    field bool flag
end

struct Loose
    field varvalue anything
end
)";

constexpr std::string_view kPlanSvc = "example.plan";

const robdef::ServiceDefinitionSet& plan_lookup() {
    static const robdef::ServiceDefinitionSet set = make_lookup({kExampleTestRobdef, kExampleOtherRobdef, kPlanRobdef});
    return set;
}

std::shared_ptr<const Plan> plan_of(const robdef::TypeDefinition& t) {
    return Plan::compile(t, plan_lookup(), kPlanSvc);
}

// The general path's text, or nullopt where it reports an error.
std::optional<std::string> general_text(const MessageElement& e, const robdef::TypeDefinition& t) {
    auto v = unpack_value(e, t, plan_lookup(), kPlanSvc);
    if (!v) return std::nullopt;
    auto j = value_to_json(*v, t, plan_lookup(), kPlanSvc);
    if (!j) return std::nullopt;
    return j->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

MessageElement element_from_json(const nlohmann::json& j, const robdef::TypeDefinition& t) {
    auto v = value_from_json(j, t, plan_lookup(), kPlanSvc);
    INFO((v ? std::string() : v.error().message));
    REQUIRE(v);
    auto e = pack_value(*v, t, "value", plan_lookup(), kPlanSvc);
    INFO((e ? std::string() : e.error().message));
    REQUIRE(e);
    return *e;
}

// The direct text equals the general one, after a prefix it must keep.
void check_same(const MessageElement& e, std::string_view type) {
    INFO(type);
    const auto t = type_of(type);
    auto plan = plan_of(t);
    REQUIRE(plan);
    auto general = general_text(e, t);
    REQUIRE(general);
    std::string direct = "prefix:";
    REQUIRE(plan->append(direct, e));
    CHECK(direct == "prefix:" + *general);
}

nlohmann::json pose_json(double k) {
    return {{"position", {{"x", k}, {"y", 0.5}, {"z", -k}}}, {"orientation", {1, 0, 0, k}}};
}

nlohmann::json sample_json(double t) {
    return {{"t", t},
            {"ids", {1, -2, 3}},
            {"tag", {7, 255}},
            {"v", {{"x", t}, {"y", 2}, {"z", 3}}},
            {"vs", {{{"x", 1}, {"y", 2}, {"z", 3}}, {{"x", 4}, {"y", 5}, {"z", 6}}}},
            {"mat", {{"dims", {2, 2}}, {"array", {1.5, 2, 3, 4e-9}}}}};
}

nlohmann::json packet_json(double t) {
    return {{"s", sample_json(t)},
            {"more", {sample_json(t + 1)}},
            {"grid", {{"dims", {2, 1}}, {"array", {sample_json(5), sample_json(6)}}}},
            {"n", 9}};
}

nlohmann::json state_json(std::uint64_t seqno, nlohmann::json next) {
    return {{"seqno", seqno},
            {"mode", 3},
            {"color", 5},
            {"name", "arm \"one\"\\\n\t\x01\x1f\x7f/é漢😀"},
            {"q", {0.1, -2.5, 1e300, "NaN", "-Infinity", 3.0}},
            {"tcp", {pose_json(1), pose_json(-0.25)}},
            {"v", {{"x", 1}, {"y", 2}, {"z", 3}}},
            {"sample", sample_json(0.5)},
            {"packets", {packet_json(1), packet_json(2)}},
            {"inners", {{{"a", 1}, {"s", "x"}}, {{"a", -7}, {"s", ""}}}},
            {"by_id", {{"10", {1.0}}, {"9", nlohmann::json::array()}, {"-3", {2.5, 3.5}}}},
            {"labels", {{"b", "B"}, {"a\"\n", "quoted"}, {"é", "accent"}, {"", "empty"}}},
            {"grid", {{"dims", {2, 3}}, {"array", {1, 2, 3, 4, 5, 6}}}},
            {"fixed", {{"dims", {2, 3}}, {"array", {0, 1, 2, 253, 254, 255}}}},
            {"next", std::move(next)},
            {"maybe", nullptr},
            {"c", {{"re", 1.5}, {"im", -0.0}}},
            {"flag", true}};
}

// --- random breakage ------------------------------------------------------------------------------

void collect(MessageElement& e, std::vector<MessageElement*>& all) {
    all.push_back(&e);
    for (auto& c : e.elements) collect(c, all);
}

constexpr DataTypes kTypes[] = {DataTypes::void_t,      DataTypes::double_t,   DataTypes::int32_t,
                                DataTypes::uint32_t,    DataTypes::uint8_t,    DataTypes::uint64_t,
                                DataTypes::string_t,    DataTypes::cdouble_t,  DataTypes::bool_t,
                                DataTypes::structure_t, DataTypes::vector_t,   DataTypes::dictionary_t,
                                DataTypes::list_t,      DataTypes::pod_t,      DataTypes::pod_array_t,
                                DataTypes::namedarray_array_t, DataTypes::multidimarray_t};

const char* const kNames[] = {"", "0", "1", "2", "-1", "array", "dims", "x", "y", "name", "next", "q",
                              "a\"b\\c\n\x01", "é", "\xff\xfe", "example.test.Vec3", "example.test.Inner",
                              "example.plan.State", "example.test.Sample"};

void mutate(MessageElement& root, std::mt19937_64& rng) {
    std::vector<MessageElement*> all;
    collect(root, all);
    auto pick = [&](std::size_t n) { return static_cast<std::size_t>(rng() % n); };
    MessageElement& e = *all[pick(all.size())];
    switch (pick(11)) {
        case 0: {  // new bytes, same size: any number, any string
            std::vector<std::byte> b(e.data.size());
            for (auto& x : b) x = static_cast<std::byte>(rng() % 4 ? rng() % 128 : rng());
            e.data = SharedBytes::copy_of(b);
            break;
        }
        case 1: {  // another size
            std::vector<std::byte> b(pick(3) == 0 ? 0 : pick(40));
            for (auto& x : b) x = static_cast<std::byte>(rng());
            e.data = SharedBytes::copy_of(b);
            break;
        }
        case 2: e.type = kTypes[pick(std::size(kTypes))]; break;
        case 3: e.type_name = kNames[pick(std::size(kNames))]; break;
        case 4: e.name = kNames[pick(std::size(kNames))]; break;
        case 5:
            if (e.number) e.number.reset();
            else e.number = static_cast<std::int32_t>(pick(4)) - 1;
            break;
        case 6:
            if (!e.elements.empty()) e.elements.erase(e.elements.begin() + static_cast<std::ptrdiff_t>(pick(e.elements.size())));
            break;
        case 7:
            if (!e.elements.empty()) e.elements.push_back(e.elements[pick(e.elements.size())]);
            break;
        case 8:
            if (e.elements.size() > 1) std::swap(e.elements[pick(e.elements.size())], e.elements[pick(e.elements.size())]);
            break;
        case 9: {  // null in its place, keeping the name
            MessageElement null;
            null.name = e.name;
            null.number = e.number;
            e = std::move(null);
            break;
        }
        default:  // a sibling's name: a duplicate field or map key
            if (e.elements.size() > 1) e.elements[pick(e.elements.size())].name = e.elements[pick(e.elements.size())].name;
            break;
    }
}

}  // namespace

TEST_CASE("element JSON plan: structs, pods, namedarrays, enums, strings and containers render as the general path does") {
    const auto state = type_of("State");
    const auto inner = state_json(2, nullptr);
    const auto outer = state_json(std::numeric_limits<std::uint64_t>::max(), inner);
    check_same(element_from_json(outer, state), "State");
    check_same(element_from_json(nullptr, state), "State");
    check_same(element_from_json(nlohmann::json::array({outer, inner}), type_of("State{list}")), "State{list}");
    check_same(element_from_json({{"k", inner}, {"", nullptr}}, type_of("State{string}")), "State{string}");
    check_same(element_from_json(nullptr, type_of("State{int32}")), "State{int32}");
    check_same(element_from_json({pose_json(1), pose_json(2), pose_json(3)}, type_of("example.test.Pose[]")),
               "example.test.Pose[]");
    check_same(element_from_json(pose_json(4), type_of("example.test.Pose")), "example.test.Pose");
    check_same(element_from_json(nlohmann::json::array(), type_of("example.test.Pose[]")), "example.test.Pose[]");
    check_same(element_from_json(packet_json(3), type_of("example.test.Packet")), "example.test.Packet");
    check_same(element_from_json({sample_json(1), sample_json(2)}, type_of("example.test.Sample[2]")),
               "example.test.Sample[2]");
    check_same(element_from_json({{"dims", {1, 2, 2}}, {"array", {1, 2, 3, 4}}}, type_of("double[*]")), "double[*]");
    check_same(element_from_json(1, type_of("Mode")), "Mode");
    check_same(element_from_json({{"a", 3}, {"s", "ok"}}, type_of("example.test.Inner")), "example.test.Inner");
    check_same(element_from_json({"a", std::string("b\0c", 3)}, type_of("string{list}")), "string{list}");
    check_same(element_from_json({{"7", 1}, {"-7", 2}, {"70", 3}}, type_of("int32{int32}")), "int32{int32}");
    check_same(element_from_json({{"k", {{"dims", {1}}, {"array", {1}}}}}, type_of("double[*]{string}")),
               "double[*]{string}");
    // Unqualified names resolve in the context service, as the general path resolves them.
    check_same(element_from_json({{"a", 1}, {"s", "x"}}, type_of("example.test.Inner")), "example.test.Inner");
}

// The general text with each null member of an object left out, recursively (nulls in arrays stay).
void drop_null_members(nlohmann::json& j) {
    if (j.is_object()) {
        for (auto it = j.begin(); it != j.end();) {
            if (it->is_null()) it = j.erase(it);
            else drop_null_members(*it++);
        }
    } else if (j.is_array()) {
        for (auto& x : j) drop_null_members(x);
    }
}

void check_same_without_nulls(const MessageElement& e, std::string_view type) {
    INFO(type);
    const auto t = type_of(type);
    auto plan = plan_of(t);
    REQUIRE(plan);
    auto general = general_text(e, t);
    REQUIRE(general);
    auto want = nlohmann::json::parse(*general);
    drop_null_members(want);
    std::string direct = "prefix:";
    REQUIRE(plan->append(direct, e, /*omit_null_members=*/true));
    CHECK(direct == "prefix:" + want.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

TEST_CASE("element JSON plan: omit_null_members leaves null struct fields and map entries out, as the recorder wants") {
    const auto state = type_of("State");
    auto inner = state_json(2, nullptr);  // next and maybe null
    inner["inners"] = nullptr;
    inner["labels"] = nullptr;
    inner["by_id"] = nullptr;
    const auto outer = state_json(7, inner);
    check_same_without_nulls(element_from_json(outer, state), "State");
    check_same_without_nulls(element_from_json(inner, state), "State");
    check_same_without_nulls(element_from_json(nullptr, state), "State");  // the value itself: null stays
    // the first, a middle and the last entry null: no stray comma
    check_same_without_nulls(element_from_json({{"", nullptr}, {"k", inner}, {"m", nullptr}, {"z", nullptr}}, type_of("State{string}")),
                             "State{string}");
    check_same_without_nulls(element_from_json({{"1", nullptr}, {"2", nullptr}}, type_of("State{int32}")), "State{int32}");
    // nulls in a list stay
    check_same_without_nulls(element_from_json(nlohmann::json::array({nullptr, inner, nullptr}), type_of("State{list}")), "State{list}");
    // a varvalue written by the general path: a null one is left out too
    Structure loose{"example.plan.Loose", {{"anything", Value()}}};
    auto e = pack_value(Value(loose), type_of("Loose"), "value", plan_lookup(), kPlanSvc);
    REQUIRE(e);
    check_same_without_nulls(*e, "Loose");
    // without the option, nulls are written as the general path writes them
    check_same(element_from_json(inner, state), "State");
}

TEST_CASE("element JSON plan: every byte of a string and of a map key is escaped as nlohmann escapes it") {
    std::string all;
    for (int c = 1; c < 0x80; ++c) all += static_cast<char>(c);
    all += std::string("\0", 1);
    all += "é漢😀\xef\xbf\xbf";
    MessageElement s = string_element(all);
    check_same(s, "string");
    MessageElement map;
    map.type = DataTypes::dictionary_t;
    for (int c = 0; c < 0x80; c += 5) {
        MessageElement item = string_element("v");
        item.name = std::string(1, static_cast<char>(c)) + "k" + std::string(1, static_cast<char>(c + 1));
        map.elements.push_back(std::move(item));
    }
    check_same(map, "string{string}");
}

TEST_CASE("element JSON plan: a type with nothing to write directly gets no plan, others hand such parts to the general path") {
    for (const char* type : {"varvalue", "example.test.Vec3[*]", "example.test.Sample[*]", "example.test.Nope", "Mode[]"}) {
        INFO(type);
        CHECK_FALSE(plan_of(type_of(type)));
    }
    for (const char* type : {"State", "void", "Loose", "example.test.Outer", "example.test.Holder", "varvalue{list}"}) {
        INFO(type);
        CHECK(plan_of(type_of(type)));
    }
    // The test values touching every kind: a recursive struct with varvalue, multi-dim and container
    // fields, pods with multi-dim pod fields, a varvalue map of named values.
    for (const auto& [value, type] : rich_values()) {
        const std::string qualified = type.rfind("varvalue", 0) == 0 ? type : "example.test." + type;
        auto e = pack_value(value, type_of(qualified), "value", plan_lookup(), kPlanSvc);
        INFO(qualified);
        REQUIRE(e);
        check_same(*e, qualified);
    }
    Structure loose{"example.plan.Loose", {{"anything", Value(samples({1, 2}))}}};
    auto e = pack_value(Value(loose), type_of("Loose"), "value", plan_lookup(), kPlanSvc);
    REQUIRE(e);
    check_same(*e, "Loose");
    check_same(element_from_json(nlohmann::json::array({nullptr, {{"type", "string"}, {"value", "x"}}}), type_of("varvalue{list}")),
               "varvalue{list}");
}

TEST_CASE("element JSON plan: broken element trees render as the general path or are declined, never otherwise") {
    std::mt19937_64 rng(20261125);
    const auto inner = state_json(2, nullptr);
    struct Case {
        std::string type;
        MessageElement element;
    };
    std::vector<Case> cases;
    const auto state = type_of("State");
    cases.push_back({"State", element_from_json(state_json(1, inner), state)});
    cases.push_back({"example.test.Pose[]", element_from_json({pose_json(1), pose_json(2)}, type_of("example.test.Pose[]"))});
    cases.push_back({"example.test.Packet[2-]", element_from_json(nlohmann::json::array({packet_json(1)}), type_of("example.test.Packet[2-]"))});
    cases.push_back({"string{string}", element_from_json({{"a", "x"}, {"b", "y"}}, type_of("string{string}"))});
    cases.push_back({"double[]{int32}", element_from_json({{"1", {1.0}}, {"2", {2.0}}}, type_of("double[]{int32}"))});
    cases.push_back({"int32[*]", element_from_json({{"dims", {2}}, {"array", {1, 2}}}, type_of("int32[*]"))});
    for (const auto& [value, type] : rich_values()) {  // with general parts: varvalue, multi-dim pods
        const std::string qualified = type.rfind("varvalue", 0) == 0 ? type : "example.test." + type;
        auto e = pack_value(value, type_of(qualified), "value", plan_lookup(), kPlanSvc);
        REQUIRE(e);
        cases.push_back({qualified, *e});
    }
    std::size_t rendered = 0, refused = 0, declined_only = 0;
    for (const auto& c : cases) {
        const auto t = type_of(c.type);
        auto plan = plan_of(t);
        REQUIRE(plan);
        for (int i = 0; i < 1500; ++i) {
            MessageElement e = c.element;
            for (std::size_t k = 0, n = 1 + rng() % 3; k < n; ++k) mutate(e, rng);
            auto general = general_text(e, t);
            std::string direct = "prefix:";
            const bool ok = plan->append(direct, e);
            INFO(c.type << " case " << i);
            if (!general) {
                CHECK_FALSE(ok);  // never text where the general path reports an error
                CHECK(direct == "prefix:");
                ++refused;
            } else if (ok) {
                CHECK(direct == "prefix:" + *general);
                ++rendered;
            } else {
                ++declined_only;
            }
        }
    }
    INFO("rendered " << rendered << ", refused " << refused << ", declined only " << declined_only);
    // The breakage reaches both outcomes, and the plan declines little the general path renders
    // (only what it cannot tell from the type: none expected here).
    CHECK(rendered > 1000);
    CHECK(refused > 1000);
    CHECK(declined_only == 0);
}

TEST_CASE("element JSON plan: nesting beyond Limits::max_nesting_depth is declined, as the general path refuses it") {
    const auto t = type_of("State");
    nlohmann::json j = nullptr;
    for (int i = 0; i < 80; ++i) j = state_json(static_cast<std::uint64_t>(i), j);
    Limits deep;
    deep.max_nesting_depth = 1000;
    auto v = value_from_json(j, t, plan_lookup(), kPlanSvc, deep);
    REQUIRE(v);
    auto e = pack_value(*v, t, "value", plan_lookup(), kPlanSvc, deep);
    REQUIRE(e);
    CHECK_FALSE(unpack_value(*e, t, plan_lookup(), kPlanSvc));  // default limits: too deep
    auto plan = Plan::compile(t, plan_lookup(), kPlanSvc);
    std::string out;
    CHECK_FALSE(plan->append(out, *e));
    CHECK(out.empty());
    auto deep_plan = Plan::compile(t, plan_lookup(), kPlanSvc, deep);
    auto dv = unpack_value(*e, t, plan_lookup(), kPlanSvc, deep);
    REQUIRE(dv);
    auto dj = value_to_json(*dv, t, plan_lookup(), kPlanSvc, deep);
    REQUIRE(dj);
    REQUIRE(deep_plan->append(out, *e));
    CHECK(out == dj->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}
