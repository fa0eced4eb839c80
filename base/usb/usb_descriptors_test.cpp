// rr+usb descriptors: the BOS platform capability, the RR descriptor set, string descriptors and the
// standard descriptor table, each from hand-written bytes laid out as wire.md §10 / CORE describe.
#include <catch2/catch.hpp>

#include <vector>

#include "base/usb/usb_descriptor_table.hpp"
#include "base/usb/usb_descriptors.hpp"

using namespace rr;
using namespace rr::usb;

namespace {

std::vector<std::byte> bytes(std::initializer_list<int> v) {
    std::vector<std::byte> out;
    for (int b : v) out.push_back(static_cast<std::byte>(b));
    return out;
}

std::vector<std::byte> cat(std::vector<std::byte> a, const std::vector<std::byte>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

bool mentions(const RRError& e, std::string_view what) { return e.message.find(what) != std::string::npos; }

// The RR capability: bLength 24, DEVICE CAPABILITY, PLATFORM, reserved, UUID, version 0x0100, iface, code.
std::vector<std::byte> rr_capability(int iface, int code, int version_lo = 0x00, int version_hi = 0x01) {
    return bytes({24,   0x10, 0x05, 0,    0xc3, 0x0e, 0x67, 0x84, 0xc6, 0xce, 0x17, 0x49, 0xb0, 0x39, 0x51, 0x0e,
                  0x3e, 0x71, 0x78, 0x8b, version_lo, version_hi, iface, code});
}
// WebUSB's platform capability (another UUID), and a USB 2.0 extension capability.
const std::vector<std::byte> kWebUsb = bytes({24,   0x10, 0x05, 0,    0x38, 0xB6, 0x08, 0x34, 0xA9, 0x09, 0xA0, 0x47,
                                              0x8B, 0xFD, 0xA0, 0x76, 0x88, 0x15, 0xB6, 0x65, 0x00, 0x01, 0x01, 0x00});
const std::vector<std::byte> kUsb2Ext = bytes({7, 0x10, 0x02, 0x06, 0, 0, 0});

std::vector<std::byte> bos(std::vector<std::vector<std::byte>> caps) {
    std::vector<std::byte> body;
    for (auto& c : caps) body = cat(body, c);
    const auto total = 5 + body.size();
    return cat(bytes({5, 0x0F, int(total & 0xFF), int(total >> 8), int(caps.size())}), body);
}

}  // namespace

TEST_CASE("usb: the RR platform capability is found in a BOS among other capabilities") {
    auto found = find_platform_capabilities(bos({kUsb2Ext, kWebUsb, rr_capability(2, 0xBA)}));
    REQUIRE(found);
    REQUIRE(found->size() == 1);
    CHECK((*found)[0] == PlatformCapability{2, 0xBA});

    // What we build is what CORE reads: 29 bytes, the capability body at offset 9.
    const auto built = build_bos_descriptor({1, 0x42});
    CHECK(built == bos({rr_capability(1, 0x42)}));
    auto again = find_platform_capabilities(built);
    REQUIRE(again);
    CHECK(*again == std::vector<PlatformCapability>{{1, 0x42}});

    // No RR capability, a wrong version, or a wrong size: none found (skipped as CORE does).
    auto none = find_platform_capabilities(bos({kUsb2Ext, kWebUsb}));
    REQUIRE(none);
    CHECK(none->empty());
    auto old = find_platform_capabilities(bos({rr_capability(0, 0xBA, 0x00, 0x02)}));
    REQUIRE(old);
    CHECK(old->empty());
    auto odd = rr_capability(0, 0xBA);
    odd[0] = std::byte{25};
    odd.push_back(std::byte{0});
    auto odd_found = find_platform_capabilities(bos({odd}));
    REQUIRE(odd_found);
    CHECK(odd_found->empty());
}

TEST_CASE("usb: malformed BOS descriptors are protocol errors") {
    auto short_header = find_platform_capabilities(bytes({5, 0x0F, 5}));
    REQUIRE_FALSE(short_header);
    CHECK(short_header.error().type == MessageErrorType::ProtocolError);
    auto wrong_type = find_platform_capabilities(bytes({5, 0x02, 5, 0, 0}));
    REQUIRE_FALSE(wrong_type);
    CHECK(mentions(wrong_type.error(), "descriptor type 2"));
    auto too_long = find_platform_capabilities(bytes({5, 0x0F, 40, 0, 1}));
    REQUIRE_FALSE(too_long);
    CHECK(mentions(too_long.error(), "wTotalLength 40 but 5 bytes present"));
    auto zero_cap = find_platform_capabilities(cat(bytes({5, 0x0F, 8, 0, 1}), bytes({0, 0x10, 5})));
    REQUIRE_FALSE(zero_cap);
    CHECK(mentions(zero_cap.error(), "bLength 0"));
    auto past = find_platform_capabilities(cat(bytes({5, 0x0F, 8, 0, 1}), bytes({24, 0x10, 5})));
    REQUIRE_FALSE(past);
    CHECK(mentions(past.error(), "runs past wTotalLength"));
}

TEST_CASE("usb: the RR descriptor set parses from CORE's layout and round-trips") {
    // header {8, 0, 0x0100, 24}; interface descriptor {16, 1, 0, 0x0100, iNodeID 4, iNodeName 5, 2, 0x0101, 0x0200}
    const auto set = bytes({8, 0, 0, 0, 0x00, 0x01, 24, 0, 16, 0, 1, 0, 0, 0, 0x00, 0x01, 4, 5, 2, 0, 0x01, 0x01, 0x00, 0x02});
    auto total = parse_descriptor_set_length(set);
    REQUIRE(total);
    CHECK(*total == 24);
    auto d = parse_descriptor_set(set);
    REQUIRE(d);
    CHECK(d->node_id_string == 4);
    CHECK(d->node_name_string == 5);
    CHECK(d->protocols == std::vector<std::uint16_t>{0x0101, 0x0200});
    CHECK(d->supports_stream_protocol());

    // Unknown records are skipped; built sets parse back to the same values.
    auto with_other = cat(bytes({8, 0, 0, 0, 0x00, 0x01, 32, 0, 8, 0, 7, 0, 1, 0, 0xAA, 0xBB}),
                          bytes({16, 0, 1, 0, 0, 0, 0x00, 0x01, 4, 5, 2, 0, 0x01, 0x01, 0x00, 0x02}));
    auto d2 = parse_descriptor_set(with_other);
    REQUIRE(d2);
    CHECK(*d2 == *d);
    auto built = build_descriptor_set(*d);
    CHECK(built == set);
    DescriptorSet defaulted;
    defaulted.node_id_string = 9;
    auto parsed = parse_descriptor_set(build_descriptor_set(defaulted));
    REQUIRE(parsed);
    CHECK(parsed->protocols == std::vector<std::uint16_t>{kStreamProtocol});
}

TEST_CASE("usb: malformed RR descriptor sets are protocol errors, never loops or over-reads") {
    auto header = [](int type, int version, int total) {
        return bytes({8, 0, type & 0xFF, type >> 8, version & 0xFF, version >> 8, total & 0xFF, total >> 8});
    };
    const auto iface = bytes({12, 0, 1, 0, 0, 0, 0x00, 0x01, 4, 5, 0, 0});
    struct Case {
        std::vector<std::byte> in;
        const char* says;
    } cases[] = {
        {bytes({8, 0, 0}), "shorter than its 8-byte header"},
        {cat(header(2, 0x0100, 20), iface), "wDescriptorType 2"},
        {cat(header(0, 0x0200, 20), iface), "version 0x0200"},
        {cat(header(0, 0x0100, 4), iface), "wTotalLength 4 shorter"},
        {cat(header(0, 0x0100, 64), iface), "wTotalLength 64 but 20 bytes present"},
        // a zero-length record: CORE spins forever on it
        {cat(header(0, 0x0100, 14), bytes({0, 0, 1, 0, 0, 0})), "record of wLength 0"},
        {cat(header(0, 0x0100, 12), bytes({6, 0, 1, 0})), "truncated record"},
        {cat(header(0, 0x0100, 20), bytes({30, 0, 1, 0, 0, 0, 0x00, 0x01, 4, 5, 0, 0})), "runs past wTotalLength"},
        {cat(header(0, 0x0100, 16), bytes({8, 0, 1, 0, 0, 0, 0x00, 0x01})), "interface descriptor of 8 bytes"},
        {cat(header(0, 0x0100, 20), bytes({12, 0, 1, 0, 0, 0, 0x00, 0x02, 4, 5, 0, 0})), "interface descriptor version 0x0200"},
        // wNumProtocols 200 in a 12-byte record: CORE reads 400 bytes past it
        {cat(header(0, 0x0100, 20), bytes({12, 0, 1, 0, 0, 0, 0x00, 0x01, 4, 5, 200, 0})), "lists 200 protocols"},
        {cat(cat(header(0, 0x0100, 32), iface), iface), "second interface descriptor"},
        {cat(header(0, 0x0100, 16), bytes({8, 0, 7, 0, 0, 0, 0, 0})), "no interface descriptor"},
    };
    for (const auto& c : cases) {
        auto r = parse_descriptor_set(c.in);
        INFO(c.says);
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::ProtocolError);
        INFO(r.error().message);
        CHECK(mentions(r.error(), c.says));
    }
}

TEST_CASE("usb: string descriptors carry UTF-16LE text") {
    auto d = build_string_descriptor("RR-Node \xC3\xA9\xF0\x9F\xA4\x96");  // é and a non-BMP robot face
    REQUIRE(d);
    CHECK(static_cast<int>((*d)[0]) == int(d->size()));
    CHECK(static_cast<int>((*d)[1]) == 3);
    CHECK(d->size() == 2 + 2 * (8 + 1 + 2));
    auto text = parse_string_descriptor(*d);
    REQUIRE(text);
    CHECK(*text == "RR-Node \xC3\xA9\xF0\x9F\xA4\x96");

    // "AB\0C": text ends at the NUL, as CORE's conversion does.
    auto nul = parse_string_descriptor(bytes({10, 3, 'A', 0, 'B', 0, 0, 0, 'C', 0}));
    REQUIRE(nul);
    CHECK(*nul == "AB");

    auto langs = parse_language_ids(build_language_ids());
    REQUIRE(langs);
    CHECK(*langs == 0x0409);
    CHECK_FALSE(parse_language_ids(bytes({2, 3})));
    CHECK_FALSE(parse_language_ids(bytes({4, 2, 9, 4})));

    CHECK(mentions(parse_string_descriptor(bytes({6, 3, 'A', 0})).error(), "bLength 6 but 4 bytes"));
    CHECK(mentions(parse_string_descriptor(bytes({4, 2, 'A', 0})).error(), "descriptor type 2"));
    CHECK(mentions(parse_string_descriptor(bytes({3, 3, 'A'})).error(), "odd length"));
    CHECK(mentions(parse_string_descriptor(bytes({4, 3, 0x00, 0xD8})).error(), "unpaired high surrogate"));
    CHECK(mentions(parse_string_descriptor(bytes({4, 3, 0x00, 0xDC})).error(), "unpaired low surrogate"));

    CHECK_FALSE(build_string_descriptor("\xC3"));                  // truncated
    CHECK_FALSE(build_string_descriptor("\xC0\x80"));              // overlong
    CHECK_FALSE(build_string_descriptor("\xED\xA0\x80"));          // a surrogate in UTF-8
    CHECK(build_string_descriptor(std::string(126, 'x')));
    auto too_long = build_string_descriptor(std::string(127, 'x'));
    REQUIRE_FALSE(too_long);
    CHECK(too_long.error().type == MessageErrorType::InvalidArgument);
}

TEST_CASE("usb: the descriptor table answers standard GET_DESCRIPTOR requests") {
    DeviceLayout layout;
    layout.vendor_id = 0x1209;
    layout.product_id = 0x0001;
    layout.max_packet_size = 64;
    DeviceStrings strings;
    strings.node_id = NodeID::parse("{6f1b1f3c-2f4e-4a1e-9d6c-0123456789ab}").value();
    strings.node_name = "usb_demo";
    DeviceFunctionConfig fn;
    auto t = DescriptorTable::build(layout, strings, fn);
    REQUIRE(t);
    auto get = [&](int type, int index) { return t->get_descriptor(SetupPacket{0x80, 6, std::uint16_t(type << 8 | index), 0, 255}); };
    auto dev = get(1, 0);
    REQUIRE(dev);
    REQUIRE(dev->size() == 18);
    CHECK(static_cast<int>((*dev)[8]) == 0x09);   // idVendor low
    CHECK(static_cast<int>((*dev)[9]) == 0x12);
    CHECK(static_cast<int>((*dev)[2]) == 0x10);   // bcdUSB 2.10
    auto cfg = get(2, 0);
    REQUIRE(cfg);
    CHECK(cfg->size() == 32);
    CHECK(static_cast<int>((*cfg)[9 + 5]) == 0xFF);  // bInterfaceClass vendor
    CHECK(static_cast<int>((*cfg)[18 + 4]) == 64);   // wMaxPacketSize of the first endpoint
    auto b = get(0x0F, 0);
    REQUIRE(b);
    auto caps = find_platform_capabilities(*b);
    REQUIRE(caps);
    CHECK(*caps == std::vector<PlatformCapability>{{0, 0xBA}});
    auto id = get(3, fn.node_id_string);
    REQUIRE(id);
    CHECK(parse_string_descriptor(*id).value() == "6f1b1f3c-2f4e-4a1e-9d6c-0123456789ab");
    CHECK(parse_string_descriptor(get(3, fn.node_name_string).value()).value() == "usb_demo");
    CHECK(parse_language_ids(get(3, 0).value()).value() == 0x0409);
    CHECK_FALSE(get(3, 77));
    CHECK(t->sysfs_descriptors().size() == 18 + 32);

    auto no_bos = DescriptorTable::build(layout, strings, fn, false);
    REQUIRE(no_bos);
    CHECK(no_bos->bos().empty());
    CHECK_FALSE(no_bos->get_descriptor(SetupPacket{0x80, 6, 0x0F00, 0, 5}));

    DeviceStrings anonymous;
    CHECK_FALSE(DescriptorTable::build(layout, anonymous, fn));
    DeviceFunctionConfig clash;
    clash.node_id_string = 1;  // the manufacturer's index
    CHECK_FALSE(DescriptorTable::build(layout, strings, clash));
}
