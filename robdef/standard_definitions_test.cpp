// The standard definitions (robdef-standard/group1, group2) and the seed paper's examples, read from
// RR_SHARED_DIR, with the verdicts of the official parser/verifier (robdef.md §14, seed README).
#include <catch2/catch.hpp>

#include "robdef/canonical_text.hpp"
#include "robdef/parser.hpp"
#include "robdef/service_definition_set.hpp"
#include "robdef/test_support.hpp"
#include "robdef/verifier.hpp"

using namespace rr::robdef;
using rr::robdef::test::count;
using rr::robdef::test::dump;
using rr::robdef::test::read_text;
using rr::robdef::test::robdef_files;
using rr::robdef::test::shared_path;

namespace {

// Parses every file of `files` into `set`; returns all parse diagnostics.
std::vector<Diagnostic> load(ServiceDefinitionSet& set, const std::vector<std::filesystem::path>& files) {
    std::vector<Diagnostic> all;
    for (const auto& f : files) {
        auto r = parse_service_definition_report(read_text(f), f.filename().string());
        INFO(f.string() << "\n" << dump(r.diagnostics));
        REQUIRE(r.ok());
        all.insert(all.end(), r.diagnostics.begin(), r.diagnostics.end());
        set.add(std::move(*r.definition));
    }
    return all;
}

}  // namespace

TEST_CASE("group1 standard definitions parse and verify as one set without diagnostics", "[shared]") {
    auto dir = shared_path("robdef-standard/group1");
    if (!dir) RR_SKIP("robdef-standard/ not found in the shared test data folder " << rr::test::shared_dir());
    auto files = robdef_files(*dir);
    REQUIRE(files.size() == 45);
    ServiceDefinitionSet set;
    auto parse_diags = load(set, files);
    CHECK(parse_diags.empty());
    auto diags = set.verify();
    INFO(dump(diags));
    CHECK(diags.empty());
    CHECK(set.size() == 46);  // 45 + built-in ServiceIndex

    SECTION("named types are resolved across imports and through using") {
        const auto* robot = set.find_service("com.robotraconteur.robotics.robot");
        REQUIRE(robot);
        const auto* obj = robot->find_entry("Robot");
        REQUIRE(obj);
        CHECK(obj->implements.at(0) == "com.robotraconteur.device.Device");
        const auto* info = obj->find_member("robot_info");
        REQUIRE(info);
        CHECK(info->type.named_kind == NamedTypeKind::structure);
        CHECK(info->type.qualified_name == "com.robotraconteur.robotics.robot.RobotInfo");
        CHECK(info->modifiers == std::vector<std::string>{"readonly", "nolock"});
        auto ref = set.find("com.robotraconteur.geometry.Pose");
        REQUIRE(ref);
        REQUIRE(ref.entry);
        CHECK(ref.entry->kind == EntryKind::namedarray);
        auto uuid = set.find("UUID", "com.robotraconteur.uuid");
        REQUIRE(uuid);
        CHECK(uuid.entry->members.at(0).type.to_string() == "uint8[16]");
        auto code = set.find("ActionStatusCode", "com.robotraconteur.action");
        REQUIRE(code.enumeration);
    }
}

TEST_CASE("group2 planning fails with the unknown import error, scene alone verifies", "[shared]") {
    auto g1 = shared_path("robdef-standard/group1");
    auto g2 = shared_path("robdef-standard/group2");
    if (!g1 || !g2) RR_SKIP("robdef-standard/ not found in the shared test data folder " << rr::test::shared_dir());
    auto files = robdef_files(*g1);
    SECTION("pair") {
        auto all = files;
        all.push_back(*g2 / "com.robotraconteur.a1.robotics.planning.robdef");
        all.push_back(*g2 / "com.robotraconteur.a1.robotics.scene.robdef");
        ServiceDefinitionSet set;
        load(set, all);
        auto diags = set.verify();
        REQUIRE(has_errors(diags));
        const Diagnostic& first = diags.front();
        CHECK(first.kind == DiagnosticKind::import);
        CHECK(first.message == "Service definition \"com.robotraconteur.a1.robotics.scene\" not found");
        CHECK(first.file == "com.robotraconteur.a1.robotics.planning.robdef");
        CHECK(first.line == 11);
    }
    SECTION("scene alone") {
        auto all = files;
        all.push_back(*g2 / "com.robotraconteur.a1.robotics.scene.robdef");
        ServiceDefinitionSet set;
        load(set, all);
        auto diags = set.verify();
        INFO(dump(diags));
        CHECK(diags.empty());
    }
}

TEST_CASE("seed examples give the official verdicts", "[shared]") {
    auto dir = shared_path("seed-examples");
    if (!dir) RR_SKIP("seed-examples/ not found in the shared test data folder " << rr::test::shared_dir());
    auto check_one = [&](const std::string& name) {
        auto r = parse_service_definition_report(read_text(*dir / name), name);
        INFO(dump(r.diagnostics));
        REQUIRE(r.ok());
        std::vector<Diagnostic> all = r.diagnostics;
        std::vector<ServiceDefinition> defs{*r.definition};
        auto v = verify_service_definitions(defs);
        all.insert(all.end(), v.begin(), v.end());
        return all;
    };
    SECTION("createwebcam: only deprecation warnings") {
        auto d = check_one("experimental.createwebcam.robdef");
        INFO(dump(d));
        REQUIRE_FALSE(d.empty());
        for (const auto& x : d) {
            CHECK(x.severity == Severity::warning);
            CHECK(x.message == "option keyword is deprecated");
        }
    }
    SECTION("minimal_create: only deprecation warnings") {
        auto d = check_one("experimental.minimal_create.robdef");
        INFO(dump(d));
        CHECK(count(d, Severity::error) == 0);
        for (const auto& x : d) CHECK(x.message == "option keyword is deprecated");
    }
    SECTION("create: the dotted constant fails verification at line 11") {
        auto d = check_one("experimental.create.robdef");
        INFO(dump(d));
        REQUIRE(has_errors(d));
        auto it = std::find_if(d.begin(), d.end(), [](const Diagnostic& x) { return x.is_error(); });
        CHECK(it->message == "could not parse constant \"constant int16 DRIVE.STRAIGHT 32767\"");
        CHECK(it->line == 11);
        CHECK(it->kind == DiagnosticKind::constant);
    }
}

TEST_CASE("to_string round trip is stable over the standard and seed definitions", "[shared]") {
    std::vector<std::filesystem::path> files;
    for (const char* sub : {"robdef-standard/group1", "robdef-standard/group2", "seed-examples"})
        if (auto d = shared_path(sub))
            for (auto& f : robdef_files(*d)) files.push_back(f);
    if (files.empty()) RR_SKIP("no robdefs in the shared test data folder " << rr::test::shared_dir());
    ServiceDefinitionSet canonical_set;
    std::size_t group1 = 0;
    for (const auto& f : files) {
        INFO(f.string());
        auto r1 = parse_service_definition(read_text(f), f.filename().string());
        REQUIRE(r1);
        std::string t1 = to_string(r1->definition);
        auto r2 = parse_service_definition(t1, "canonical");
        INFO(t1);
        REQUIRE(r2);
        std::string t2 = to_string(r2->definition);
        CHECK(t1 == t2);
        CHECK(r2->definition.name == r1->definition.name);
        if (f.parent_path().filename() == "group1") {
            ++group1;
            canonical_set.add(std::move(r2->definition));
        }
    }
    if (group1 > 0) {
        auto diags = canonical_set.verify();
        INFO(dump(diags));
        CHECK(diags.empty());
    }
}
