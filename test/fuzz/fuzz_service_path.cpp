// libFuzzer target for the name parsers of core/: service paths and objref indices
// (base/names/service_path.hpp, wire.md §6.5) and the type strings of varvalues received from peers
// (core/value/var_type.hpp). Properties checked: a split path re-joins to the same path; an index
// decodes back from its encoding; renaming the service keeps the rest of the path; a parsed type
// string prints back to a type string that parses to the same type.
// Input: the text. Seeds: test/fuzz/seeds/fuzz_service_path.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "base/names/service_path.hpp"
#include "core/value/var_type.hpp"

namespace {

void check(bool ok, const char* what) {
    if (!ok) {
        std::fprintf(stderr, "fuzz_service_path: %s\n", what);
        std::abort();
    }
}

bool same_type(const rr::robdef::TypeDefinition& a, const rr::robdef::TypeDefinition& b) {
    return a.base == b.base && a.type_name == b.type_name && a.array == b.array &&
           a.array_var_length == b.array_var_length && a.array_length == b.array_length && a.container == b.container;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > 4096) return 0;
    const std::string_view text(reinterpret_cast<const char*>(data), size);

    // Any bytes are a valid index: encoding then decoding gives them back.
    auto decoded = rr::decode_service_path_index(rr::encode_service_path_index(text));
    check(decoded.ok() && *decoded == text, "index encoding does not round-trip");
    (void)rr::decode_service_path_index(text);

    if (auto segments = rr::split_service_path(text)) {
        check(!segments->empty(), "a split path has segments");
        std::string joined = (*segments)[0].name;
        if ((*segments)[0].has_index) joined += "[" + rr::encode_service_path_index((*segments)[0].index) + "]";
        for (std::size_t i = 1; i < segments->size(); ++i) {
            const auto& s = (*segments)[i];
            joined = s.has_index ? rr::join_service_path(joined, s.name, s.index) : rr::join_service_path(joined, s.name);
        }
        auto again = rr::split_service_path(joined);
        check(again.ok() && again->size() == segments->size(), "a re-joined path does not split the same way");
        for (std::size_t i = 0; i < segments->size(); ++i)
            check((*again)[i].name == (*segments)[i].name && (*again)[i].index == (*segments)[i].index &&
                      (*again)[i].has_index == (*segments)[i].has_index,
                  "a re-joined path has different segments");
        const std::string renamed = rr::replace_service_name(text, "dev");
        check(rr::service_name_of(renamed) == "dev", "renamed path does not start with the new service");
        check(renamed.substr(3) == text.substr(rr::service_name_of(text).size()), "renaming changed the rest");
    }

    if (auto t = rr::parse_type_string(text)) {
        auto back = rr::parse_type_string(t->to_string());
        check(back.ok(), "a parsed type string prints to text that does not parse");
        check(same_type(*t, *back), "a parsed type string prints to a different type");
    }
    return 0;
}
