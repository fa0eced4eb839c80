// ServiceDefinitionSet: built-in ServiceIndex, lookup (TypeLookup), replacement, resolution.
#include <catch2/catch.hpp>

#include "robdef/builtin/service_index.hpp"
#include "robdef/canonical_text.hpp"
#include "robdef/parser.hpp"
#include "robdef/service_definition_set.hpp"
#include "robdef/test_support.hpp"

using namespace rr::robdef;
using rr::robdef::test::dump;

TEST_CASE("a new set holds the built-in RobotRaconteurServiceIndex, which verifies") {
    ServiceDefinitionSet set;
    REQUIRE(set.size() == 1);
    const auto* idx = set.find_service(kServiceIndexServiceName);
    REQUIRE(idx);
    CHECK_FALSE(idx->stdver);
    const auto* obj = idx->find_entry("ServiceIndex");
    REQUIRE(obj);
    CHECK(obj->kind == EntryKind::object);
    const auto* f = obj->find_member("GetLocalNodeServices");
    REQUIRE(f);
    CHECK(f->type.to_string() == "ServiceInfo{int32}");
    CHECK(f->type.named_kind == NamedTypeKind::structure);
    CHECK(f->type.qualified_name == "RobotRaconteurServiceIndex.ServiceInfo");
    const auto* node = idx->find_entry("NodeInfo");
    REQUIRE(node);
    CHECK(node->find_member("NodeID")->type.to_string() == "uint8[16]");
    CHECK(idx->find_entry("ServiceInfo")->find_member("Attributes")->type.to_string() == "varvalue{string}");
    auto diags = set.verify();
    INFO(dump(diags));
    CHECK(diags.empty());
    auto ref = set.find(kServiceIndexObjectType);
    REQUIRE(ref);
    CHECK(ref.entry == obj);
}

TEST_CASE("lookup: qualified, unqualified in context, using alias, enums, replacement") {
    ServiceDefinitionSet set;
    REQUIRE(set.add_text("service c.d\nstdver 0.10\nenum Mode\n    a = 0\nend\npod P\n    field double x\nend\n", "c.robdef"));
    auto w = set.add_text(
        "service a.b\nstdver 0.10\nimport c.d\nusing c.d.P as Pt\nstruct S\n    field Pt p\n    field c.d.Mode m\n"
        "    field Missing q\nend\n",
        "a.robdef");
    REQUIRE(w);
    CHECK(w->empty());
    CHECK(set.size() == 3);

    CHECK(set.find("c.d.P").entry->kind == EntryKind::pod);
    CHECK(set.find("P", "c.d"));
    CHECK_FALSE(set.find("P", "a.b"));  // the alias is Pt
    CHECK(set.find("Pt", "a.b").entry->name == "P");
    CHECK(set.find("Mode", "c.d").enumeration);
    CHECK_FALSE(set.find("Mode", "a.b"));
    CHECK_FALSE(set.find("x.y.Z"));
    CHECK_FALSE(set.find("P"));

    const auto& s = set.find_service("a.b")->structures.at(0);
    CHECK(s.members[0].type.type_name == "c.d.P");
    CHECK(s.members[0].type.named_kind == NamedTypeKind::pod);
    CHECK(s.members[0].type.qualified_name == "c.d.P");
    CHECK(s.members[1].type.named_kind == NamedTypeKind::enumeration);
    CHECK(s.members[2].type.named_kind == NamedTypeKind::unresolved);
    CHECK(s.members[2].type.qualified_name.empty());

    // Replacing c.d without P leaves a.b's reference unresolved.
    REQUIRE(set.add_text("service c.d\nstdver 0.10\n", "c2.robdef"));
    CHECK(set.size() == 3);
    CHECK(set.find_service("a.b")->structures.at(0).members[0].type.named_kind == NamedTypeKind::unresolved);

    auto bad = set.add_text("service x.y\nfoo\n", "bad.robdef");
    REQUIRE_FALSE(bad);
    CHECK(bad.error().message == "bad.robdef:2: Parse error");
    CHECK(set.size() == 3);
}

TEST_CASE("built-in text round-trips through the canonical form") {
    auto r = parse_service_definition(service_index_robdef(), "idx");
    REQUIRE(r);
    const std::string t = to_string(r->definition);
    CHECK(t.find("struct NodeInfo\n    field string NodeName\n    field uint8[16] NodeID\n") != std::string::npos);
    CHECK(t.find("    event LocalNodeServicesChanged()\n") != std::string::npos);
    auto r2 = parse_service_definition(t, "idx2");
    REQUIRE(r2);
    CHECK(to_string(r2->definition) == t);
}
