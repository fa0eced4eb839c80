// Test-only: the hand-built services used by the value tests. As robdef text:
//
//   service example.test
//   enum Color  red = 0, green = 1, blue = 5  end
//   struct Inner     field int32 a  field string s  end
//   struct Outer     field Inner inner  field Inner maybe  field double[3] v  field double[2-] b
//                    field double[*] m  field int32[2,2] fixed  field string{list} names
//                    field Inner{string} by_name  field varvalue any  field Color color
//                    field cdouble c  field bool flag  field uint8[] bytes  field Outer next  end
//   namedarray Vec3  field double x  field double y  field double z  end
//   namedarray Pose  field Vec3 position  field double[4] orientation  end
//   pod Sample       field double t  field int32[3] ids  field uint8[4-] tag  field Vec3 v
//                    field Vec3[2] vs  field double[2,2] mat  end
//   pod Packet       field Sample s  field Sample[2-] more  field Sample[2,1] grid  field uint16 n  end
//   struct Holder    field Sample one  field Sample[] many  field Sample[2] pair  field Sample[*] cube
//                    field Vec3 p  field Vec3[] ps  field Vec3[*] pgrid  field Pose pose  field Packet pk  end
//
//   service example.other
//   struct Local     field int8 k  end
//   struct Wrapper   field example.test.Inner inner  field Local local  end
#pragma once

#include "core/value/test_lookup.hpp"

namespace rr::testing {

inline const TestLookup& example_lookup() {
    static const TestLookup lookup = [] {
        using robdef::EntryKind;
        TestLookup l;
        auto& t = l.add("example.test");
        t.enums.push_back(enumeration("Color", {{"red", 0}, {"green", 1}, {"blue", 5}}));
        t.structures.push_back(entry(EntryKind::structure, "Inner", {field("int32", "a"), field("string", "s")}));
        t.structures.push_back(entry(
            EntryKind::structure, "Outer",
            {field("Inner", "inner"), field("Inner", "maybe"), field("double[3]", "v"), field("double[2-]", "b"),
             field("double[*]", "m"), field("int32[2,2]", "fixed"), field("string{list}", "names"),
             field("Inner{string}", "by_name"), field("varvalue", "any"), field("Color", "color"),
             field("cdouble", "c"), field("bool", "flag"), field("uint8[]", "bytes"), field("Outer", "next")}));
        t.namedarrays.push_back(
            entry(EntryKind::namedarray, "Vec3", {field("double", "x"), field("double", "y"), field("double", "z")}));
        t.namedarrays.push_back(
            entry(EntryKind::namedarray, "Pose", {field("Vec3", "position"), field("double[4]", "orientation")}));
        t.pods.push_back(entry(EntryKind::pod, "Sample",
                               {field("double", "t"), field("int32[3]", "ids"), field("uint8[4-]", "tag"),
                                field("Vec3", "v"), field("Vec3[2]", "vs"), field("double[2,2]", "mat")}));
        t.pods.push_back(entry(EntryKind::pod, "Packet",
                               {field("Sample", "s"), field("Sample[2-]", "more"), field("Sample[2,1]", "grid"),
                                field("uint16", "n")}));
        t.structures.push_back(entry(
            EntryKind::structure, "Holder",
            {field("Sample", "one"), field("Sample[]", "many"), field("Sample[2]", "pair"), field("Sample[*]", "cube"),
             field("Vec3", "p"), field("Vec3[]", "ps"), field("Vec3[*]", "pgrid"), field("Pose", "pose"),
             field("Packet", "pk")}));
        auto& o = l.add("example.other");
        o.structures.push_back(entry(EntryKind::structure, "Local", {field("int8", "k")}));
        o.structures.push_back(
            entry(EntryKind::structure, "Wrapper", {field("example.test.Inner", "inner"), field("Local", "local")}));
        return l;
    }();
    return lookup;
}

}  // namespace rr::testing
