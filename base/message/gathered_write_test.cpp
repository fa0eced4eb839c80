// Gathered output (issue 14): large shared payloads are spliced into a GatherBuffer instead of copied,
// the pieces in order are exactly the bytes a contiguous encoding gives, and errors and limits roll
// the buffer back whole.
#include <catch2/catch.hpp>

#include <numeric>

#include "base/codec/gather_buffer.hpp"
#include "base/message/encoded_entry.hpp"
#include "base/message/message_reader.hpp"
#include "base/message/message_writer.hpp"

using namespace rr;

namespace {

const NodeID kSender = NodeID::parse("11111111-2222-3333-4444-555555555555").value();
const NodeID kReceiver = NodeID::parse("aaaaaaaa-bbbb-cccc-dddd-eeeeeeeeeeee").value();

std::vector<std::byte> pattern(std::size_t n, unsigned seed) {
    std::vector<std::byte> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::byte>((i * 31 + seed) & 0xff);
    return v;
}

MessageElement bytes_element(std::string name, SharedBytes data) {
    MessageElement e;
    e.name = std::move(name);
    e.type = DataTypes::uint8_t;
    e.data = std::move(data);
    return e;
}

// An Echo-like reply: a small element, a large one, a nested structure with another large one.
Message reply_with_arrays(std::uint16_t version, const SharedBytes& big, const SharedBytes& nested_big) {
    Message m;
    m.version = version;
    m.header.sender_node_id = kSender;
    m.header.receiver_node_id = kReceiver;
    auto& e = m.entries.emplace_back();
    e.entry_type = MessageEntryType::FunctionCallRes;
    e.service_path = "bench";
    e.member_name = "Echo";
    e.request_id = 9;
    e.elements.push_back(bytes_element("small", SharedBytes::copy_of(pattern(100, 1))));
    e.elements.push_back(bytes_element("return", big));
    MessageElement s;
    s.name = "s";
    s.type = DataTypes::structure_t;
    s.type_name = "x.y";
    s.elements.push_back(bytes_element("image", nested_big));
    e.elements.push_back(std::move(s));
    return m;
}

std::vector<std::byte> joined(const GatherBuffer& g) {
    std::vector<std::byte> out;
    g.for_each_piece([&](std::span<const std::byte> p) { out.insert(out.end(), p.begin(), p.end()); });
    return out;
}

}  // namespace

TEST_CASE("codec: a GatherBuffer splices large owned ranges and copies the rest") {
    GatherBuffer g;
    const auto head = pattern(10, 1);
    g.append(std::span<const std::byte>(head));
    const auto big = SharedBytes::adopt(pattern(GatherBuffer::kSpliceMinBytes, 2));
    g.append(big);
    const auto small = SharedBytes::adopt(pattern(GatherBuffer::kSpliceMinBytes - 1, 3));
    g.append(small);
    const auto unowned_bytes = pattern(2 * GatherBuffer::kSpliceMinBytes, 4);
    g.append(SharedBytes(nullptr, unowned_bytes));  // a view without owner: copied, it may die first
    g.append(big);                                   // the same range twice: two splices

    REQUIRE(g.splices().size() == 2);
    CHECK(g.splices()[0].at == 10);
    CHECK(g.splices()[0].bytes.data() == big.data());
    CHECK(g.splices()[1].at == 10 + small.size() + unowned_bytes.size());
    CHECK(g.spliced_bytes() == 2 * big.size());
    CHECK(g.owned().size() == 10 + small.size() + unowned_bytes.size());
    CHECK(g.size() == g.owned().size() + 2 * big.size());

    std::vector<std::byte> expected(head);
    for (const auto& part : {big, small}) expected.insert(expected.end(), part.bytes().begin(), part.bytes().end());
    expected.insert(expected.end(), unowned_bytes.begin(), unowned_bytes.end());
    expected.insert(expected.end(), big.bytes().begin(), big.bytes().end());
    CHECK(joined(g) == expected);

    // Rolling back to a mark drops the splices and bytes after it.
    const auto mark = g.mark();
    g.append(big);
    g.append(std::span<const std::byte>(head));
    g.rollback(mark);
    CHECK(joined(g) == expected);

    // Flattening copies the splices in and keeps the stream.
    g.flatten();
    CHECK(g.splices().empty());
    CHECK(g.spliced_bytes() == 0);
    CHECK(g.owned() == expected);

    GatherBuffer other;
    other.append(big);
    other.swap(g);
    CHECK(g.size() == big.size());
    CHECK(other.owned() == expected);
    g.clear();
    CHECK(g.empty());
    CHECK(g.size() == 0);
}

TEST_CASE("message: encoding into a GatherBuffer splices large payloads and equals the contiguous bytes") {
    const auto big = SharedBytes::adopt(pattern(100'000, 5));
    const auto nested_big = SharedBytes::adopt(pattern(20'000, 6));
    for (std::uint16_t version : {2, 4}) {
        INFO("format " << version);
        const Message m = reply_with_arrays(version, big, nested_big);
        std::vector<std::byte> contiguous;
        REQUIRE(encode_message(m, contiguous));

        GatherBuffer g;
        g.append(std::span<const std::byte>(pattern(3, 7)));  // something already queued
        REQUIRE(encode_message(m, g));
        REQUIRE(g.splices().size() == 2);
        CHECK(g.splices()[0].bytes.data() == big.data());
        CHECK(g.splices()[1].bytes.data() == nested_big.data());
        // Only the bytes that are not spliced were reserved and copied.
        CHECK(g.owned().size() == 3 + contiguous.size() - big.size() - nested_big.size());
        auto all = joined(g);
        REQUIRE(all.size() == 3 + contiguous.size());
        CHECK(std::equal(contiguous.begin(), contiguous.end(), all.begin() + 3));

        // The decoded message re-encodes with views into its frame: those get spliced too.
        auto decoded = decode_message(SharedBytes::adopt(std::move(contiguous)), Limits{});
        REQUIRE(decoded);
        GatherBuffer again;
        REQUIRE(encode_message(*decoded, again));
        CHECK(again.splices().size() == 2);
        CHECK(joined(again) == std::vector<std::byte>(all.begin() + 3, all.end()));
    }
}

TEST_CASE("message: a GatherBuffer is left as it was when encoding fails") {
    const auto big = SharedBytes::adopt(pattern(50'000, 8));
    Message m = reply_with_arrays(4, big, big);
    MessageElement odd;
    odd.name = "odd";
    odd.type = DataTypes::double_t;
    odd.data = SharedBytes::copy_of(pattern(7, 9));  // not a multiple of 8: refused while measuring
    m.entries[0].elements.push_back(std::move(odd));
    GatherBuffer g;
    g.append(big);
    const auto before = joined(g);
    CHECK_FALSE(encode_message(m, g));
    CHECK(g.splices().size() == 1);
    CHECK(joined(g) == before);
}

TEST_CASE("message: a large encoded entry is spliced into each message and equals the whole encoding") {
    MessageEntry entry;
    entry.entry_type = MessageEntryType::WirePacket;
    entry.service_path = "camera";
    entry.member_name = "frame";
    entry.elements.push_back(bytes_element("value", SharedBytes::adopt(pattern(30'000, 10))));
    auto shared = std::make_shared<const EncodedEntry>(entry);
    for (std::uint16_t version : {2, 4}) {
        INFO("format " << version);
        Message header;
        header.version = version;
        header.header.sender_node_id = kSender;
        header.header.receiver_node_id = kReceiver;
        Message whole = header;
        whole.entries.push_back(entry);
        std::vector<std::byte> expected;
        REQUIRE(encode_message(whole, expected));

        auto bytes = shared->shared_bytes(version);
        REQUIRE(bytes);
        CHECK(bytes->owner() != nullptr);  // kept alive by the entry itself
        GatherBuffer g;
        REQUIRE(encode_message(header, *bytes, g));
        REQUIRE(g.splices().size() == 1);
        CHECK(g.splices()[0].bytes.data() == bytes->data());
        CHECK(joined(g) == expected);
        // Below `owned_from` bytes: a view without owner (a sender copies those).
        auto small = shared->shared_bytes(version, bytes->size() + 1);
        REQUIRE(small);
        CHECK(small->owner() == nullptr);
        CHECK(small->data() == bytes->data());
        CHECK(shared->shared_bytes(version, bytes->size())->owner() != nullptr);
    }
    // An entry not held by a shared_ptr gives a view without owner: copied, never spliced.
    const EncodedEntry local(entry);
    auto view = local.shared_bytes(4);
    REQUIRE(view);
    CHECK(view->owner() == nullptr);
    CHECK_FALSE(GatherBuffer::splices(*view));
}
