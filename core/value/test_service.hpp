// Test-only: the service definitions used by the value tests, parsed by robdef's ServiceDefinitionSet
// (the same TypeLookup the gateway uses), plus a type-string shortcut.
#pragma once

#include <catch2/catch.hpp>

#include <initializer_list>
#include <string_view>

#include "core/value/var_type.hpp"
#include "robdef/service_definition_set.hpp"

namespace rr::testing {

inline constexpr std::string_view kExampleTestRobdef = R"(service example.test
stdver 0.10

enum Color
    red = 0,
    green = 1,
    blue = 5
end

struct Inner
    field int32 a
    field string s
end

struct Outer
    field Inner inner
    field Inner maybe
    field double[3] v
    field double[2-] b
    field double[*] m
    field int32[2,2] fixed
    field string{list} names
    field Inner{string} by_name
    field varvalue any
    field Color color
    field cdouble c
    field bool flag
    field uint8[] bytes
    field Outer next
end

namedarray Vec3
    field double x
    field double y
    field double z
end

namedarray Pose
    field Vec3 position
    field double[4] orientation
end

pod Sample
    field double t
    field int32[3] ids
    field uint8[4-] tag
    field Vec3 v
    field Vec3[2] vs
    field double[2,2] mat
end

pod Packet
    field Sample s
    field Sample[2-] more
    field Sample[2,1] grid
    field uint16 n
end

struct Holder
    field Sample one
    field Sample[] many
    field Sample[2] pair
    field Sample[*] cube
    field Vec3 p
    field Vec3[] ps
    field Vec3[*] pgrid
    field Pose pose
    field Packet pk
end
)";

inline constexpr std::string_view kExampleOtherRobdef = R"(service example.other
stdver 0.10
import example.test

struct Local
    field int8 k
end

struct Wrapper
    field example.test.Inner inner
    field Local local
end
)";

/// A set holding example.test and example.other (parse errors abort the test run).
inline robdef::ServiceDefinitionSet make_lookup(std::initializer_list<std::string_view> texts) {
    robdef::ServiceDefinitionSet set;
    for (auto text : texts) {
        auto r = set.add_text(text, "test.robdef");
        if (!r) {
            FAIL(r.error().message);
        }
    }
    return set;
}

inline const robdef::ServiceDefinitionSet& example_lookup() {
    static const robdef::ServiceDefinitionSet set = make_lookup({kExampleTestRobdef, kExampleOtherRobdef});
    return set;
}

/// Parses a type string such as "double[3]" or "example.test.Vec3[*]"; aborts on a typo in the test.
inline robdef::TypeDefinition type_of(std::string_view text) { return parse_type_string(text).value(); }

}  // namespace rr::testing
