// Test-only: a TypeLookup over hand-built ServiceDefinitions, and small builders for them.
// (robdef/ will provide ServiceDefinitionSet; until then value and JSON tests use this.)
#pragma once

#include <deque>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>

#include "core/value/var_type.hpp"
#include "robdef/service_definition.hpp"
#include "robdef/type_lookup.hpp"

namespace rr::testing {

/// Parses a type string such as "double[3]" or "example.test.Point"; aborts on a typo in the test.
inline robdef::TypeDefinition type_of(std::string_view text) { return parse_type_string(text).value(); }

inline robdef::MemberDefinition field(std::string_view type_text, std::string name) {
    robdef::MemberDefinition m;
    m.kind = robdef::MemberKind::field;
    m.name = std::move(name);
    m.type = type_of(type_text);
    m.type.name = m.name;
    return m;
}

inline robdef::ServiceEntryDefinition entry(robdef::EntryKind kind, std::string name,
                                            std::initializer_list<robdef::MemberDefinition> fields) {
    robdef::ServiceEntryDefinition e;
    e.kind = kind;
    e.name = std::move(name);
    e.members.assign(fields.begin(), fields.end());
    return e;
}

inline robdef::EnumDefinition enumeration(std::string name,
                                          std::initializer_list<std::pair<std::string, std::int32_t>> values) {
    robdef::EnumDefinition e;
    e.name = std::move(name);
    for (const auto& [n, v] : values) {
        robdef::EnumValue ev;
        ev.name = n;
        ev.value = v;
        e.values.push_back(ev);
    }
    return e;
}

/// Finds types by `svc.Type` (split at the last dot) or by `Type` in the context service.
/// Services live in a deque so pointers stay valid while more are added.
class TestLookup : public robdef::TypeLookup {
public:
    robdef::ServiceDefinition& add(std::string service_name) {
        services.emplace_back();
        services.back().name = std::move(service_name);
        return services.back();
    }

    robdef::NamedTypeRef find(std::string_view type_name, std::string_view context_service) const override {
        std::string_view svc = context_service, name = type_name;
        if (auto dot = type_name.rfind('.'); dot != std::string_view::npos) {
            svc = type_name.substr(0, dot);
            name = type_name.substr(dot + 1);
        }
        for (const auto& s : services) {
            if (s.name != svc) continue;
            robdef::NamedTypeRef r;
            if (const auto* e = s.find_entry(name)) {
                r.service = &s;
                r.entry = e;
            } else if (const auto* en = s.find_enum(name)) {
                r.service = &s;
                r.enumeration = en;
            }
            return r;
        }
        return {};
    }

    std::deque<robdef::ServiceDefinition> services;
};

}  // namespace rr::testing
