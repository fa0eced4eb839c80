// libFuzzer target for the rr+usb descriptor parsers (base/usb/usb_descriptors.hpp): the first byte
// picks the parser, the rest is the descriptor. Whatever parses must build again and parse to the
// same value; nothing may read past the input (ASan) or loop (libFuzzer's timeout).
// Seeds: test/fuzz/seeds/fuzz_usb_descriptors (a BOS with the RR capability, a descriptor set,
// string descriptors).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "base/usb/usb_descriptors.hpp"

namespace {

void check(bool ok) {
    if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace rr::usb;
    if (size == 0) return 0;
    const std::span<const std::byte> in(reinterpret_cast<const std::byte*>(data + 1), size - 1);
    switch (data[0] % 4) {
        case 0: {
            auto caps = find_platform_capabilities(in);
            if (caps) {
                for (const auto& c : *caps) {
                    auto again = find_platform_capabilities(build_bos_descriptor(c));
                    check(again.ok() && again->size() == 1 && (*again)[0] == c);
                }
            }
            break;
        }
        case 1: {
            auto len = parse_descriptor_set_length(in);
            auto set = parse_descriptor_set(in);
            if (set) {
                check(len.ok() && *len <= in.size());
                auto built = build_descriptor_set(*set);
                auto again = parse_descriptor_set(built);
                check(again.ok());
                if (!set->protocols.empty()) check(*again == *set);
            }
            break;
        }
        case 2: {
            auto text = parse_string_descriptor(in);
            if (text) {
                auto built = build_string_descriptor(*text);
                check(built.ok());  // a parsed string always fits again (NUL ends it earlier if anything)
                auto again = parse_string_descriptor(*built);
                check(again.ok() && *again == *text);
            }
            break;
        }
        default: {
            auto lang = parse_language_ids(in);
            if (lang) check(in.size() >= 4);
            break;
        }
    }
    return 0;
}
