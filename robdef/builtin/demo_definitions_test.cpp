// The modernized seed definitions served by the demo devices (experimental.create,
// experimental.createwebcam): they verify without any diagnostic, and have exactly the members of the
// paper's originals (seed-examples/, read from RR_SHARED_DIR when present).
#include <catch2/catch.hpp>

#include <map>
#include <sstream>

#include "robdef/builtin/experimental_create.hpp"
#include "robdef/builtin/experimental_createwebcam.hpp"
#include "robdef/parser.hpp"
#include "robdef/service_definition_set.hpp"
#include "robdef/test_support.hpp"

using namespace rr::robdef;

namespace {

/// entry.member -> "kind type(params)" for every struct and object of `def`.
std::map<std::string, std::string> member_signatures(const ServiceDefinition& def) {
    std::map<std::string, std::string> out;
    auto add = [&](const std::vector<ServiceEntryDefinition>& entries) {
        for (const auto& e : entries)
            for (const auto& m : e.members) {
                std::string sig = std::string(member_kind_keyword(m.kind)) + " " + m.type.to_string() + "(";
                for (const auto& p : m.parameters) sig += p.to_string() + ",";
                out[e.name + "." + m.name] = sig + ")";
            }
    };
    add(def.structures);
    add(def.objects);
    return out;
}

ServiceDefinition parse_ok(std::string_view text, std::string_view file) {
    auto r = parse_service_definition_report(text, file);
    INFO(test::dump(r.diagnostics));
    REQUIRE(r.ok());
    CHECK(r.diagnostics.empty());
    return std::move(*r.definition);
}

}  // namespace

TEST_CASE("demo definitions parse and verify together without diagnostics") {
    ServiceDefinitionSet set;
    auto w1 = set.add_text(experimental_create_robdef(), "experimental.create.robdef");
    REQUIRE(w1);
    CHECK(w1->empty());
    auto w2 = set.add_text(experimental_createwebcam_robdef(), "experimental.createwebcam.robdef");
    REQUIRE(w2);
    CHECK(w2->empty());
    auto diags = set.verify();
    INFO(test::dump(diags));
    CHECK(diags.empty());

    const auto* create = set.find_service(kExperimentalCreateServiceName);
    REQUIRE(create);
    REQUIRE(create->stdver);
    CHECK(create->stdver->to_string() == "0.10");
    const auto* obj = create->find_entry("Create");
    REQUIRE(obj);
    REQUIRE(obj->constants.size() == 3);
    std::map<std::string, std::string> constants;
    for (const auto& c : obj->constants) constants[c.name] = c.value;
    CHECK(constants["DRIVE_STRAIGHT"] == std::to_string(kCreateDriveStraight));
    CHECK(constants["SPIN_CLOCKWISE"] == std::to_string(kCreateSpinClockwise));
    CHECK(constants["SPIN_COUNTERCLOCKWISE"] == std::to_string(kCreateSpinCounterClockwise));

    auto ref = set.find(kExperimentalWebcamImage);
    REQUIRE(ref);
    REQUIRE(set.find(kExperimentalWebcamHostObjectType));
    REQUIRE(set.find(kExperimentalWebcamObjectType));
    REQUIRE(set.find(kExperimentalCreateObjectType));
    REQUIRE(set.find(kExperimentalCreateSensorPacket));
    REQUIRE(set.find(kExperimentalWebcamImageSize));
}

TEST_CASE("demo definitions have exactly the members of the paper's definitions", "[shared]") {
    auto dir = test::shared_path("seed-examples");
    if (!dir) RR_SKIP("seed-examples/ not found in the shared test data folder " << rr::test::shared_dir());
    struct Pair {
        const char* file;
        std::string_view ours;
    };
    for (const Pair& p : {Pair{"experimental.create.robdef", experimental_create_robdef()},
                          Pair{"experimental.createwebcam.robdef", experimental_createwebcam_robdef()}}) {
        INFO(p.file);
        auto seed = parse_service_definition_report(test::read_text(*dir / p.file), p.file);
        INFO(test::dump(seed.diagnostics));
        REQUIRE(seed.ok());  // legacy syntax: parses (with warnings)
        auto ours = parse_ok(p.ours, p.file);
        CHECK(ours.name == seed.definition->name);
        CHECK(member_signatures(ours).size() >= 10);
        CHECK(member_signatures(ours) == member_signatures(*seed.definition));
        REQUIRE(ours.objects.size() == seed.definition->objects.size());
        for (std::size_t i = 0; i < ours.objects.size(); ++i) {
            // The paper's constant names with dots become underscores; values stay.
            std::map<std::string, std::string> a, b;
            for (const auto& c : ours.objects[i].constants) a[c.name] = c.type.to_string() + " " + c.value;
            // Legacy `option constant <type> <name> <value>` lines are kept as options.
            for (const auto& o : seed.definition->objects[i].options) {
                std::istringstream words(o);
                std::string kw, type, name, value;
                words >> kw >> type >> name >> value;
                if (kw != "constant") continue;
                for (auto& ch : name)
                    if (ch == '.') ch = '_';
                b[name] = type + " " + value;
            }
            CHECK(a == b);
        }
    }
}
