// Malformed input: every size and count is checked before use, and each failure has the documented
// error type (ProtocolError for malformed bytes, BufferLimitViolation for Limits).
#include <catch2/catch.hpp>

#include <cstdio>
#include <cstdlib>

#include "base/codec/endian.hpp"
#include "base/message/for_each_split.hpp"
#include "base/message/message_reader.hpp"
#include "base/message/message_writer.hpp"
#include "base/message/test_vectors.hpp"

using namespace rr;
using rr::test::from_hex;
using rr::test::shared;

namespace {

// Decodes `bytes` directly and through the stream framer at every split; both must fail with `type`.
void require_error(const std::vector<std::byte>& bytes, MessageErrorType type, const Limits& limits = {},
                   const DecodeContext* ctx = nullptr) {
    auto r = decode_message(shared(bytes), limits, ctx);
    REQUIRE_FALSE(r);
    INFO(r.error().message);
    if (std::getenv("RR_PRINT_ERRORS")) std::printf("%s\n", r.error().message.c_str());
    CHECK(r.error().type == type);
    rr::test::for_each_split(
        bytes,
        [&](Result<std::vector<Message>> s, std::size_t at) {
            INFO("split at " << at);
            REQUIRE_FALSE(s);
            CHECK(s.error().type == type);
        },
        limits, ctx);
}

void patch_u32(std::vector<std::byte>& b, std::size_t at, std::uint32_t v) { store_le(b.data() + at, v); }
void patch_u16(std::vector<std::byte>& b, std::size_t at, std::uint16_t v) { store_le(b.data() + at, v); }

MessageElement f64(std::string name, double v) {
    MessageElement e;
    e.name = std::move(name);
    e.type = DataTypes::double_t;
    std::array<std::byte, 8> b;
    store_le_double(b.data(), v);
    e.data = SharedBytes::copy_of(b);
    return e;
}

// v2: header 64, entry @64 (fixed 22), struct "s"/"t" @86 (fixed 18), double child "d" @104 (fixed 17 + 8).
std::vector<std::byte> nested_v2() {
    Message m;
    MessageEntry entry;
    entry.entry_type = MessageEntryType::FunctionCallReq;
    MessageElement s;
    s.name = "s";
    s.type = DataTypes::structure_t;
    s.type_name = "t";
    s.elements.push_back(f64("d", 1.5));
    entry.elements.push_back(s);
    m.entries.push_back(entry);
    std::vector<std::byte> out;
    REQUIRE(encode_message(m, out));
    REQUIRE(out.size() == 129);
    return out;
}
constexpr std::size_t kEntry = 64, kStruct = 86, kChild = 104;

// Elements nested `depth` deep (1 = one flat element) in format `version`.
std::vector<std::byte> nested_depth(std::size_t depth, std::uint16_t version) {
    MessageElement leaf = f64("leaf", 2.0);
    for (std::size_t i = 1; i < depth; ++i) {
        MessageElement parent;
        parent.name = "n";
        parent.type = DataTypes::structure_t;
        parent.elements.push_back(std::move(leaf));
        leaf = std::move(parent);
    }
    Message m;
    m.version = version;
    MessageEntry entry;
    entry.elements.push_back(std::move(leaf));
    m.entries.push_back(std::move(entry));
    std::vector<std::byte> out;
    REQUIRE(encode_message(m, out));
    return out;
}

}  // namespace

TEST_CASE("message: truncation at every offset is an error, never a crash", "[shared]") {
    for (const auto& name : rr::test::vector_names())
        if (!rr::test::load_vector(name)) RR_SKIP("shared vector " << rr::test::vector_path(name) << " not found");
    for (const auto& name : rr::test::vector_names()) {
        INFO(name);
        auto bytes = rr::test::load_vector(name);
        REQUIRE(bytes);
        for (std::size_t n = 0; n < bytes->size(); ++n) {
            INFO("truncated to " << n);
            std::vector<std::byte> cut(bytes->begin(), bytes->begin() + static_cast<std::ptrdiff_t>(n));
            auto r = decode_message(shared(cut));
            REQUIRE_FALSE(r);
            CHECK(r.error().type == MessageErrorType::ProtocolError);
            CHECK_FALSE(decode_message_header(cut));
            // The same prefix with MessageSize patched to match: the structure itself is cut short.
            if (n >= kMinMessageSize) {
                patch_u32(cut, 4, static_cast<std::uint32_t>(n));
                auto p = decode_message(shared(cut));
                REQUIRE_FALSE(p);
                CHECK(p.error().type == MessageErrorType::ProtocolError);
            }
            // A stream that ends early has no message yet and no error.
            MessageStreamReader reader;
            REQUIRE(reader.feed(std::span<const std::byte>(*bytes).first(n)));
            CHECK_FALSE(reader.take_frame());
        }
    }
}

TEST_CASE("message: wrong magic is a ProtocolError, found at the first wrong byte", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_connectiontest_v2.bin");
    for (std::size_t i = 0; i < 4; ++i) {
        INFO("byte " << i);
        auto bad = bytes;
        bad[i] = std::byte{'X'};
        require_error(bad, MessageErrorType::ProtocolError);
        MessageStreamReader reader;
        auto r = reader.feed(std::span<const std::byte>(bad).first(i + 1));
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::ProtocolError);
    }
}

TEST_CASE("message: MessageSize is checked against the limit before anything is buffered", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_connectiontest_v2.bin");
    auto bad = bytes;
    patch_u32(bad, 4, 0xFFFFFFFFu);  // 4 GiB
    require_error(bad, MessageErrorType::BufferLimitViolation);
    CHECK(decode_message_header(bad).error().type == MessageErrorType::BufferLimitViolation);
    MessageStreamReader reader;
    auto r = reader.feed(std::span<const std::byte>(bad).first(8));
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::BufferLimitViolation);
    CHECK(reader.partial_bytes() == 8);  // the preamble only; no body buffer was made

    for (std::uint32_t small : {0u, 8u, 11u}) {
        patch_u32(bad, 4, small);
        require_error(bad, MessageErrorType::ProtocolError);
    }
    patch_u32(bad, 4, 87);  // one more than the bytes given
    CHECK(decode_message(shared(bad)).error().type == MessageErrorType::ProtocolError);

    Limits limits;
    limits.max_message_size = 85;
    require_error(bytes, MessageErrorType::BufferLimitViolation, limits);
    limits.max_message_size = 86;
    CHECK(decode_message(shared(bytes), limits));
}

TEST_CASE("message: unknown message version is a ProtocolError", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_connectiontest_v2.bin");
    for (std::uint16_t v : {0, 1, 3, 5, 0xFFFF}) {
        auto bad = bytes;
        patch_u16(bad, 8, v);
        require_error(bad, MessageErrorType::ProtocolError);
    }
}

TEST_CASE("message: v2 header sizes must agree with the header fields", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "vec_connectiontest_v2.bin");  // header 64, one 22-byte entry
    for (std::uint16_t hs : {0, 63, 65, 86, 87, 0xFFFF}) {
        INFO("HeaderSize " << hs);
        auto bad = bytes;
        patch_u16(bad, 10, hs);
        require_error(bad, MessageErrorType::ProtocolError);
    }
    auto bad = bytes;
    patch_u16(bad, 52, 1);  // SenderNodeName length 1: the strings no longer end at HeaderSize
    require_error(bad, MessageErrorType::ProtocolError);
    patch_u16(bad, 52, 0xFFFF);  // past HeaderSize
    require_error(bad, MessageErrorType::ProtocolError);
}

TEST_CASE("message: v2 entry and element sizes that do not add up") {
    auto good = nested_v2();
    REQUIRE(decode_message(shared(good)));
    struct Patch {
        const char* what;
        std::size_t at;
        std::uint32_t value;
        bool u16;
    };
    const Patch patches[] = {
        {"EntrySize past the end", kEntry, 66, false},
        {"EntrySize short of its elements", kEntry, 64, false},
        {"EntrySize below the fixed fields", kEntry, 21, false},
        {"EntrySize 4 GiB", kEntry, 0xFFFFFFFF, false},
        {"ElementCount too large", kEntry + 20, 2, true},
        {"ElementCount 65535", kEntry + 20, 0xFFFF, true},
        {"struct ElementSize past its entry", kStruct, 44, false},
        {"struct ElementSize below the fixed fields", kStruct, 15, false},
        {"struct DataCount too large", kStruct + 14, 2, false},
        {"struct DataCount 4 Gi", kStruct + 14, 0xFFFFFFFF, false},
        {"child ElementSize past its parent", kChild, 26, false},
        {"child ElementSize short of its data", kChild, 24, false},
        {"child DataCount past its element", kChild + 13, 2, false},
        {"child DataCount 4 Gi", kChild + 13, 0xFFFFFFFF, false},
        {"child DataCount short of its element", kChild + 13, 0, false},
        {"child name length past its element", kChild + 4, 40, true},
    };
    for (const auto& p : patches) {
        INFO(p.what);
        auto bad = good;
        if (p.u16)
            patch_u16(bad, p.at, static_cast<std::uint16_t>(p.value));
        else
            patch_u32(bad, p.at, p.value);
        require_error(bad, MessageErrorType::ProtocolError);
    }
}

TEST_CASE("message: unknown data types and void elements with data are ProtocolErrors") {
    auto good = nested_v2();
    for (std::uint16_t t : {15, 100, 104, 105, 106, 107, 112, 113, 114, 118, 0xFFFF}) {
        INFO("type " << t);
        auto bad = good;
        patch_u16(bad, kChild + 7, t);
        require_error(bad, MessageErrorType::ProtocolError);
    }
    auto v = good;
    patch_u16(v, kChild + 7, 0);  // void with DataCount 1 (and 8 bytes left)
    require_error(v, MessageErrorType::ProtocolError);
}

TEST_CASE("message: nesting deeper than Limits::max_nesting_depth is a ProtocolError") {
    for (std::uint16_t version : {2, 4}) {
        INFO("version " << version);
        CHECK(decode_message(shared(nested_depth(64, version))));
        auto deep = nested_depth(65, version);
        require_error(deep, MessageErrorType::ProtocolError);
        Limits limits;
        limits.max_nesting_depth = 65;
        CHECK(decode_message(shared(deep), limits));
        limits.max_nesting_depth = 1;
        CHECK(decode_message(shared(nested_depth(1, version)), limits));
        CHECK(decode_message(shared(nested_depth(2, version)), limits).error().type == MessageErrorType::ProtocolError);
    }
    require_error(nested_depth(1000, 4), MessageErrorType::ProtocolError);
}

TEST_CASE("message: entry and element counts are checked against Limits", "[shared]") {
    RR_REQUIRE_VECTOR(v2, "message2.bin");  // 3 entries; 4 + 14 elements
    RR_REQUIRE_VECTOR(v4, "message4.bin");
    for (const auto* bytes : {&v2, &v4}) {
        Limits limits;
        limits.max_entries = 2;
        require_error(*bytes, MessageErrorType::BufferLimitViolation, limits);
        limits = {};
        limits.max_elements = 17;
        require_error(*bytes, MessageErrorType::BufferLimitViolation, limits);
        limits.max_elements = 18;
        CHECK(decode_message(shared(*bytes), limits));
    }
    RR_REQUIRE_VECTOR(ct, "vec_connectiontest_v2.bin");
    auto bad = ct;
    patch_u16(bad, 58, 0xFFFF);  // EntryCount 65535 with one entry's bytes
    require_error(bad, MessageErrorType::ProtocolError);
    patch_u16(bad, 58, 0);  // fewer entries than bytes
    require_error(bad, MessageErrorType::ProtocolError);
}

TEST_CASE("message: v4 header fields that do not fit") {
    // wire.md 15.4f: RRAC, size 19, version 4, HeaderLen 12, flags 0, entry 07 05 7000 00 00 00.
    const auto good = from_hex("52524143 13000000 0400 0c 00 07 05 7000 00 00 00");
    REQUIRE(decode_message(shared(good)));
    auto hdr = [&](const char* hex) { return from_hex(hex); };
    struct Case {
        const char* what;
        std::vector<std::byte> bytes;
    };
    const Case cases[] = {
        {"HeaderLen past MessageSize", hdr("52524143 13000000 0400 14 00 07 05 7000 00 00 00")},
        {"HeaderLen without the flags byte", hdr("52524143 13000000 0400 0b 00 07 05 7000 00 00 00")},
        {"HeaderLen 64-bit form", hdr("52524143 1b000000 0400 ff 1400000000000000 00 07 05 7000 00 00 00")},
        {"routing flag but no routing bytes", hdr("52524143 13000000 0400 0c 01 07 05 7000 00 00 00")},
        {"EntryCount over 65535", hdr("52524143 18000000 0400 11 40 fe 00000100 07 05 7000 00 00 00")},
        {"EntryCount with too few bytes", hdr("52524143 13000000 0400 0d 40 09 05 7000 00 00 00")},
        {"string table count with too few bytes", hdr("52524143 13000000 0400 0d 20 fc 05 7000 00 00 00")},
        {"Extended length past HeaderLen", hdr("52524143 14000000 0400 0d 80 05 07 05 7000 00 00 00")},
        {"EntrySize 64-bit form", hdr("52524143 1b000000 0400 0c 00 ff 0f00000000000000 05 7000 00 00 00")},
        {"EntrySize past the end", hdr("52524143 13000000 0400 0c 00 08 05 7000 00 00 00")},
        {"EntrySize below its fields", hdr("52524143 13000000 0400 0c 00 04 05 7000 00 00 00")},
        {"entry string past EntrySize", hdr("52524143 13000000 0400 0c 00 07 05 7000 05 00 00")},
        {"ElementCount with too few bytes", hdr("52524143 13000000 0400 0c 00 07 05 7000 00 00 01")},
        {"bytes after the last entry", hdr("52524143 14000000 0400 0c 00 07 05 7000 00 00 00 00")},
    };
    for (const auto& c : cases) {
        INFO(c.what);
        if (std::string_view(c.what) != "bytes after the last entry")
            REQUIRE(c.bytes.size() == load_le<std::uint32_t>(c.bytes.data() + 4));
        require_error(c.bytes, MessageErrorType::ProtocolError);
    }
}

TEST_CASE("message: v4 names given twice or by unknown string-table codes") {
    // One entry (type 112) with optional name fields, then one element: wire.md 2.4 / 2.5.
    struct Case {
        const char* what;
        const char* hex;
    };
    const Case cases[] = {
        {"ServicePath both string and code", "52524143 14000000 0400 0c 00 08 07 7000 00 04 00 00"},
        {"MemberName both string and code", "52524143 14000000 0400 0c 00 08 0d 7000 00 00 04 00"},
        {"unknown even code", "52524143 13000000 0400 0c 00 07 06 7000 06 00 00"},
        {"unknown standard code 312", "52524143 15000000 0400 0c 00 09 06 7000 fd3801 00 00"},
        {"odd code without a local table", "52524143 13000000 0400 0c 00 07 06 7000 01 00 00"},
        {"odd code missing from the local table",
         "52524143 17000000 0400 10 20 01 01 01 61 07 06 7000 03 00 00"},
        {"element name and number", "52524143 1a000000 0400 0c 00 0e 05 7000 00 00 01 07 05 00 00 0000 00"},
        {"element name string and code", "52524143 1a000000 0400 0c 00 0e 05 7000 00 00 01 07 03 00 00 0000 00"},
        {"element type name string and code",
         "52524143 1b000000 0400 0c 00 0f 05 7000 00 00 01 08 19 00 6500 00 00 00"},
        {"element number in 64-bit form",
         "52524143 21000000 0400 0c 00 15 05 7000 00 00 01 0e 04 7f 0100000000000000 0000 00"},
        {"element name code unknown", "52524143 19000000 0400 0c 00 0d 05 7000 00 00 01 06 02 0a 0000 00"},
    };
    for (const auto& c : cases) {
        INFO(c.what);
        auto bytes = from_hex(c.hex);
        REQUIRE(bytes.size() == load_le<std::uint32_t>(bytes.data() + 4));
        require_error(bytes, MessageErrorType::ProtocolError);
    }
    // Code 16 ("capabilities") is fine with the standard table and refused without it.
    const auto coded = from_hex("52524143 13000000 0400 0c 00 07 06 7000 10 00 00");
    auto m = decode_message(shared(coded));
    REQUIRE(m);
    CHECK(m->entries[0].service_path == "capabilities");
    CHECK(m->entries[0].service_path_code == 16);
    DecodeContext no_standard;
    no_standard.standard_string_table = false;
    require_error(coded, MessageErrorType::ProtocolError, {}, &no_standard);
    // A local code resolves from the header table; the element type name uses the same rules.
    const auto local = from_hex("52524143 1f000000 0400 11 20 01 03 02 6162 0e 09 7000 00 03 01 07 11 00 6500 03 00");
    auto lm = decode_message(shared(local));
    INFO((lm ? std::string() : lm.error().message));
    REQUIRE(lm);
    CHECK(lm->header.string_table == std::vector<std::pair<std::uint32_t, std::string>>{{3, "ab"}});
    CHECK(lm->entries[0].member_name == "ab");
    CHECK(lm->entries[0].member_name_code == 3);
    CHECK(lm->entries[0].elements[0].type_name == "ab");
    CHECK(lm->entries[0].elements[0].type_name_code == 3);
    CHECK(lm->entries[0].elements[0].type == DataTypes::structure_t);
    std::vector<std::byte> again;
    REQUIRE(encode_message(*lm, again));
    CHECK(again == local);
}

TEST_CASE("message: single-byte mutations of every vector never crash, and what decodes round-trips", "[shared]") {
    const std::uint8_t replacements[] = {0x00, 0x01, 0x7f, 0x80, 0xfd, 0xfe, 0xff};
    for (const auto& name : rr::test::vector_names())
        if (!rr::test::load_vector(name)) RR_SKIP("shared vector " << rr::test::vector_path(name) << " not found");
    std::size_t decoded = 0, rejected = 0;
    for (const auto& name : rr::test::vector_names()) {
        auto bytes = rr::test::load_vector(name);
        REQUIRE(bytes);
        for (std::size_t i = 0; i < bytes->size(); ++i) {
            for (auto v : replacements) {
                auto mutated = *bytes;
                mutated[i] = static_cast<std::byte>(v);
                auto m = decode_message(shared(mutated));
                if (!m) {
                    ++rejected;
                    const auto t = m.error().type;
                    CHECK((t == MessageErrorType::ProtocolError || t == MessageErrorType::BufferLimitViolation));
                    continue;
                }
                ++decoded;
                std::vector<std::byte> again;
                auto enc = encode_message(*m, again);
                INFO(name << " byte " << i << " = " << int(v));
                REQUIRE(enc);
                auto back = decode_message(shared(again));
                REQUIRE(back);
                CHECK(*back == *m);
            }
        }
    }
    CHECK(decoded > 0);
    CHECK(rejected > 0);
}
