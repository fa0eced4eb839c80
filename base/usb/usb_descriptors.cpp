#include "base/usb/usb_descriptors.hpp"

#include <algorithm>

#include "base/codec/endian.hpp"
#include "base/usb/usb_protocol.hpp"

namespace rr::usb {

namespace {

Unexpected bad(std::string_view where, std::string what) {
    return fail(MessageErrorType::ProtocolError, std::string(where) + ": " + std::move(what));
}

std::string num(std::size_t v) { return std::to_string(v); }

std::string hex4(std::uint16_t v) {
    static constexpr char digits[] = "0123456789abcdef";
    std::string s = "0x";
    for (int shift = 12; shift >= 0; shift -= 4) s.push_back(digits[(v >> shift) & 0xF]);
    return s;
}

std::uint16_t u16(std::span<const std::byte> b, std::size_t at) { return load_le<std::uint16_t>(b.data() + at); }
std::uint8_t u8(std::span<const std::byte> b, std::size_t at) { return static_cast<std::uint8_t>(b[at]); }

void put_u8(std::vector<std::byte>& out, std::uint8_t v) { out.push_back(static_cast<std::byte>(v)); }
void put_u16(std::vector<std::byte>& out, std::uint16_t v) {
    out.push_back(static_cast<std::byte>(v & 0xFF));
    out.push_back(static_cast<std::byte>(v >> 8));
}

}  // namespace

// --- BOS -----------------------------------------------------------------------------------------------

Result<std::vector<PlatformCapability>> find_platform_capabilities(std::span<const std::byte> bos) {
    constexpr std::string_view where = "BOS descriptor";
    if (bos.size() < kBosHeaderSize) return bad(where, num(bos.size()) + " bytes, shorter than its 5-byte header");
    if (u8(bos, 1) != kBosDescriptorType) return bad(where, "descriptor type " + num(u8(bos, 1)) + " (15 expected)");
    if (u8(bos, 0) < kBosHeaderSize) return bad(where, "bLength " + num(u8(bos, 0)) + " (5 expected)");
    const std::size_t total = u16(bos, 2);
    if (total > bos.size()) return bad(where, "wTotalLength " + num(total) + " but " + num(bos.size()) + " bytes present");
    if (total < u8(bos, 0)) return bad(where, "wTotalLength " + num(total) + " shorter than the header");
    std::vector<PlatformCapability> found;
    std::size_t pos = u8(bos, 0);
    while (pos < total) {
        if (total - pos < 3) return bad(where, "truncated capability at offset " + num(pos));
        const std::size_t len = u8(bos, pos);
        if (len < 3) return bad(where, "capability of bLength " + num(len) + " at offset " + num(pos));
        if (len > total - pos)
            return bad(where, "capability of bLength " + num(len) + " at offset " + num(pos) + " runs past wTotalLength");
        const auto cap = bos.subspan(pos, len);
        if (u8(cap, 1) == kDeviceCapabilityType && u8(cap, 2) == kPlatformCapabilityType &&
            len == kPlatformCapabilitySize &&
            std::equal(kPlatformCapabilityUuid.begin(), kPlatformCapabilityUuid.end(), cap.begin() + 4,
                       [](std::uint8_t a, std::byte b) { return a == static_cast<std::uint8_t>(b); }) &&
            u16(cap, 20) == kDescriptorVersion) {
            found.push_back(PlatformCapability{u8(cap, 22), u8(cap, 23)});
        }
        pos += len;
    }
    return found;
}

std::vector<std::byte> build_bos_descriptor(const PlatformCapability& cap) {
    std::vector<std::byte> out;
    out.reserve(kBosHeaderSize + kPlatformCapabilitySize);
    put_u8(out, kBosHeaderSize);
    put_u8(out, kBosDescriptorType);
    put_u16(out, static_cast<std::uint16_t>(kBosHeaderSize + kPlatformCapabilitySize));
    put_u8(out, 1);  // bNumDeviceCaps
    put_u8(out, kPlatformCapabilitySize);
    put_u8(out, kDeviceCapabilityType);
    put_u8(out, kPlatformCapabilityType);
    put_u8(out, 0);  // bReserved
    for (auto b : kPlatformCapabilityUuid) put_u8(out, b);
    put_u16(out, kDescriptorVersion);
    put_u8(out, cap.interface_number);
    put_u8(out, cap.vendor_code);
    return out;
}

// --- RR descriptor set ------------------------------------------------------------------------------------

bool DescriptorSet::supports_stream_protocol() const noexcept {
    return std::find(protocols.begin(), protocols.end(), kStreamProtocol) != protocols.end();
}

Result<std::uint16_t> parse_descriptor_set_length(std::span<const std::byte> header) {
    constexpr std::string_view where = "RR descriptor set";
    if (header.size() < kDescriptorSetHeaderSize)
        return bad(where, num(header.size()) + " bytes, shorter than its 8-byte header");
    if (u16(header, 2) != kDescriptorSetType) return bad(where, "wDescriptorType " + num(u16(header, 2)) + " (0 expected)");
    const auto total = u16(header, 6);
    if (total < kDescriptorSetHeaderSize) return bad(where, "wTotalLength " + num(total) + " shorter than the header");
    return total;
}

Result<DescriptorSet> parse_descriptor_set(std::span<const std::byte> bytes) {
    constexpr std::string_view where = "RR descriptor set";
    auto total = parse_descriptor_set_length(bytes);
    if (!total) return total.take_error();
    if (u16(bytes, 4) != kDescriptorVersion)
        return bad(where, "version " + hex4(u16(bytes, 4)) + " (0x0100 expected)");
    if (*total > bytes.size()) return bad(where, "wTotalLength " + num(*total) + " but " + num(bytes.size()) + " bytes present");
    if (u16(bytes, 0) > *total) return bad(where, "header wLength " + num(u16(bytes, 0)) + " beyond wTotalLength");
    const auto set = bytes.first(*total);
    std::optional<DescriptorSet> out;
    std::size_t pos = kDescriptorSetHeaderSize;
    while (pos < set.size()) {
        if (set.size() - pos < 6) return bad(where, "truncated record at offset " + num(pos));
        const std::size_t len = u16(set, pos);
        if (len < 6) return bad(where, "record of wLength " + num(len) + " at offset " + num(pos) + " (6 at least)");
        if (len > set.size() - pos)
            return bad(where, "record of wLength " + num(len) + " at offset " + num(pos) + " runs past wTotalLength");
        const auto rec = set.subspan(pos, len);
        if (u16(rec, 2) == kInterfaceDescriptorType && u16(rec, 4) == 0) {
            if (out) return bad(where, "second interface descriptor at offset " + num(pos));
            if (len < kInterfaceDescriptorMinSize)
                return bad(where, "interface descriptor of " + num(len) + " bytes (12 at least)");
            if (u16(rec, 6) != kDescriptorVersion)
                return bad(where, "interface descriptor version " + hex4(u16(rec, 6)) + " (0x0100 expected)");
            DescriptorSet d;
            d.node_id_string = u8(rec, 8);
            d.node_name_string = u8(rec, 9);
            const std::size_t n = u16(rec, 10);
            if (n > (len - kInterfaceDescriptorMinSize) / 2)
                return bad(where, "interface descriptor lists " + num(n) + " protocols in a " + num(len) + "-byte record");
            d.protocols.reserve(n);
            for (std::size_t i = 0; i < n; ++i) d.protocols.push_back(u16(rec, kInterfaceDescriptorMinSize + 2 * i));
            out = std::move(d);
        }
        pos += len;
    }
    if (!out) return bad(where, "no interface descriptor (type 1, subtype 0)");
    return std::move(*out);
}

std::vector<std::byte> build_descriptor_set(const DescriptorSet& set) {
    std::vector<std::uint16_t> protocols = set.protocols;
    if (protocols.empty()) protocols.push_back(kStreamProtocol);
    const std::size_t rec = kInterfaceDescriptorMinSize + 2 * protocols.size();
    std::vector<std::byte> out;
    out.reserve(kDescriptorSetHeaderSize + rec);
    put_u16(out, kDescriptorSetHeaderSize);
    put_u16(out, kDescriptorSetType);
    put_u16(out, kDescriptorVersion);
    put_u16(out, static_cast<std::uint16_t>(kDescriptorSetHeaderSize + rec));
    put_u16(out, static_cast<std::uint16_t>(rec));
    put_u16(out, kInterfaceDescriptorType);
    put_u16(out, 0);
    put_u16(out, kDescriptorVersion);
    put_u8(out, set.node_id_string);
    put_u8(out, set.node_name_string);
    put_u16(out, static_cast<std::uint16_t>(protocols.size()));
    for (auto p : protocols) put_u16(out, p);
    return out;
}

// --- String descriptors ----------------------------------------------------------------------------------

Result<std::uint16_t> parse_language_ids(std::span<const std::byte> bytes) {
    constexpr std::string_view where = "string descriptor 0";
    if (bytes.size() < 4) return bad(where, num(bytes.size()) + " bytes (4 at least)");
    const std::size_t len = u8(bytes, 0);
    if (len < 4 || len > bytes.size()) return bad(where, "bLength " + num(len) + " with " + num(bytes.size()) + " bytes");
    if (u8(bytes, 1) != kStringDescriptorType) return bad(where, "descriptor type " + num(u8(bytes, 1)) + " (3 expected)");
    return u16(bytes, 2);
}

Result<std::string> parse_string_descriptor(std::span<const std::byte> bytes) {
    constexpr std::string_view where = "string descriptor";
    if (bytes.size() < 2) return bad(where, num(bytes.size()) + " bytes (2 at least)");
    if (u8(bytes, 0) != bytes.size())
        return bad(where, "bLength " + num(u8(bytes, 0)) + " but " + num(bytes.size()) + " bytes transferred");
    if (u8(bytes, 1) != kStringDescriptorType) return bad(where, "descriptor type " + num(u8(bytes, 1)) + " (3 expected)");
    if (bytes.size() % 2 != 0) return bad(where, "odd length " + num(bytes.size()));
    std::string out;
    out.reserve(bytes.size());
    for (std::size_t i = 2; i < bytes.size(); i += 2) {
        std::uint32_t cp = u16(bytes, i);
        if (cp == 0) break;
        if (cp >= 0xD800 && cp <= 0xDBFF) {
            if (i + 2 >= bytes.size()) return bad(where, "unpaired high surrogate at the end");
            const std::uint32_t lo = u16(bytes, i + 2);
            if (lo < 0xDC00 || lo > 0xDFFF) return bad(where, "unpaired high surrogate");
            cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
            i += 2;
        } else if (cp >= 0xDC00 && cp <= 0xDFFF) {
            return bad(where, "unpaired low surrogate");
        }
        if (cp < 0x80) {
            out.push_back(static_cast<char>(cp));
        } else if (cp < 0x800) {
            out.push_back(static_cast<char>(0xC0 | (cp >> 6)));
            out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
        } else if (cp < 0x10000) {
            out.push_back(static_cast<char>(0xE0 | (cp >> 12)));
            out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
            out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
        } else {
            out.push_back(static_cast<char>(0xF0 | (cp >> 18)));
            out.push_back(static_cast<char>(0x80 | ((cp >> 12) & 0x3F)));
            out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
            out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
        }
    }
    return out;
}

Result<std::vector<std::byte>> build_string_descriptor(std::string_view utf8) {
    std::vector<std::uint16_t> units;
    for (std::size_t i = 0; i < utf8.size();) {
        const auto c = static_cast<std::uint8_t>(utf8[i]);
        std::uint32_t cp = 0;
        std::size_t n = 0;
        if (c < 0x80) {
            cp = c, n = 1;
        } else if ((c & 0xE0) == 0xC0) {
            cp = c & 0x1F, n = 2;
        } else if ((c & 0xF0) == 0xE0) {
            cp = c & 0x0F, n = 3;
        } else if ((c & 0xF8) == 0xF0) {
            cp = c & 0x07, n = 4;
        } else {
            return fail(MessageErrorType::InvalidArgument, "string descriptor: invalid UTF-8");
        }
        if (i + n > utf8.size()) return fail(MessageErrorType::InvalidArgument, "string descriptor: truncated UTF-8");
        for (std::size_t k = 1; k < n; ++k) {
            const auto cc = static_cast<std::uint8_t>(utf8[i + k]);
            if ((cc & 0xC0) != 0x80) return fail(MessageErrorType::InvalidArgument, "string descriptor: invalid UTF-8");
            cp = (cp << 6) | (cc & 0x3F);
        }
        static constexpr std::uint32_t kMin[] = {0, 0, 0x80, 0x800, 0x10000};
        if (cp < kMin[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
            return fail(MessageErrorType::InvalidArgument, "string descriptor: invalid UTF-8");
        if (cp >= 0x10000) {
            cp -= 0x10000;
            units.push_back(static_cast<std::uint16_t>(0xD800 + (cp >> 10)));
            units.push_back(static_cast<std::uint16_t>(0xDC00 + (cp & 0x3FF)));
        } else {
            units.push_back(static_cast<std::uint16_t>(cp));
        }
        i += n;
    }
    if (units.size() > kMaxStringUnits)
        return fail(MessageErrorType::InvalidArgument,
                    "string descriptor: " + num(units.size()) + " UTF-16 units (126 at most)");
    std::vector<std::byte> out;
    out.reserve(2 + 2 * units.size());
    put_u8(out, static_cast<std::uint8_t>(2 + 2 * units.size()));
    put_u8(out, kStringDescriptorType);
    for (auto u : units) put_u16(out, u);
    return out;
}

std::vector<std::byte> build_language_ids(std::uint16_t langid) {
    std::vector<std::byte> out;
    put_u8(out, 4);
    put_u8(out, kStringDescriptorType);
    put_u16(out, langid);
    return out;
}

// --- Standard descriptors ----------------------------------------------------------------------------------

std::vector<std::byte> build_device_descriptor(const DeviceLayout& l) {
    std::vector<std::byte> out;
    out.reserve(18);
    put_u8(out, 18);
    put_u8(out, 0x01);      // DEVICE
    put_u16(out, 0x0210);   // bcdUSB: 2.10 (BOS)
    put_u8(out, l.device_class);
    put_u8(out, 0);         // bDeviceSubClass
    put_u8(out, 0);         // bDeviceProtocol
    put_u8(out, 64);        // bMaxPacketSize0
    put_u16(out, l.vendor_id);
    put_u16(out, l.product_id);
    put_u16(out, l.bcd_device);
    put_u8(out, l.manufacturer_string);
    put_u8(out, l.product_string);
    put_u8(out, l.serial_string);
    put_u8(out, 1);         // bNumConfigurations
    return out;
}

std::vector<std::byte> build_configuration_descriptor(const DeviceLayout& l) {
    std::vector<std::byte> out;
    out.reserve(32);
    put_u8(out, 9);
    put_u8(out, 0x02);  // CONFIGURATION
    put_u16(out, 32);   // wTotalLength
    put_u8(out, 1);     // bNumInterfaces
    put_u8(out, l.configuration_value);
    put_u8(out, 0);     // iConfiguration
    put_u8(out, 0x80);  // bmAttributes: bus powered
    put_u8(out, 50);    // bMaxPower: 100 mA
    put_u8(out, 9);
    put_u8(out, 0x04);  // INTERFACE
    put_u8(out, l.interface_number);
    put_u8(out, 0);     // bAlternateSetting
    put_u8(out, 2);     // bNumEndpoints
    put_u8(out, l.interface_class);
    put_u8(out, 0);
    put_u8(out, 0);
    put_u8(out, 0);     // iInterface
    for (std::uint8_t ep : {l.in_endpoint, l.out_endpoint}) {
        put_u8(out, 7);
        put_u8(out, 0x05);  // ENDPOINT
        put_u8(out, ep);
        put_u8(out, 0x02);  // bulk
        put_u16(out, l.max_packet_size);
        put_u8(out, 0);
    }
    return out;
}

}  // namespace rr::usb
