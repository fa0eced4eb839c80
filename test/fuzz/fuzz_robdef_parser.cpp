// libFuzzer target for the robdef parser: parse arbitrary text; when it parses, the canonical text
// must parse again to the same canonical text, and verifying (alone and with the built-in set) must
// terminate without crashing.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "robdef/canonical_text.hpp"
#include "robdef/parser.hpp"
#include "robdef/service_definition_set.hpp"
#include "robdef/verifier.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > 64 * 1024) return 0;
    const std::string owned(data, data + size);
    const std::string_view text = owned;
    (void)rr::robdef::parse_type(text.substr(0, 256));
    auto r = rr::robdef::parse_service_definition(text, "fuzz.robdef");
    if (!r) return 0;
    if (r->definition.name.empty()) return 0;  // only comments: nothing to print (no `service` line)
    const std::string canonical = rr::robdef::to_string(r->definition);
    auto again = rr::robdef::parse_service_definition(canonical, "canonical.robdef");
    if (!again) std::abort();  // canonical text must parse
    if (rr::robdef::to_string(again->definition) != canonical) std::abort();  // and be stable

    rr::robdef::ServiceDefinitionSet set;
    set.add(std::move(r->definition));
    (void)set.verify();
    return 0;
}
