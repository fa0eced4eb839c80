// Stream framing: messages in any split, frames as owned buffers, limits before allocation, and a
// failed reader that stays failed.
#include <catch2/catch.hpp>

#include <algorithm>

#include "base/message/for_each_split.hpp"
#include "base/message/message_stream_reader.hpp"
#include "base/message/message_writer.hpp"
#include "base/message/test_vectors.hpp"

using namespace rr;

namespace {

struct Stream {
    std::vector<std::byte> bytes;
    std::vector<std::vector<std::byte>> messages;
};

// All available vectors back to back, as they would arrive on one connection.
Stream all_vectors() {
    Stream s;
    for (const auto& name : rr::test::vector_names()) {
        auto v = rr::test::load_vector(name);
        if (!v) continue;
        s.bytes.insert(s.bytes.end(), v->begin(), v->end());
        s.messages.push_back(std::move(*v));
    }
    return s;
}

std::vector<std::byte> bytes_of(const SharedBytes& b) { return {b.bytes().begin(), b.bytes().end()}; }

}  // namespace

TEST_CASE("message: a stream of every vector splits anywhere and yields each message in order", "[shared]") {
    Stream s = all_vectors();
    if (s.messages.size() != rr::test::vector_names().size())
        RR_SKIP("shared vectors missing under " << rr::test::vector_path(""));
    std::vector<Message> expected;
    for (const auto& m : s.messages) expected.push_back(decode_message(rr::test::shared(m)).value());
    rr::test::for_each_split(s.bytes, [&](Result<std::vector<Message>> r, std::size_t at) {
        INFO("split at " << at);
        REQUIRE(r);
        CHECK(*r == expected);
    });
    // Frames are the exact bytes, one owned buffer per message.
    MessageStreamReader reader;
    REQUIRE(reader.feed(s.bytes));
    CHECK(reader.ready_count() == s.messages.size());
    for (const auto& m : s.messages) {
        auto frame = reader.take_frame();
        REQUIRE(frame);
        CHECK(bytes_of(*frame) == m);
    }
    CHECK_FALSE(reader.take_frame());
    CHECK(reader.partial_bytes() == 0);
}

TEST_CASE("message: the stream reader accepts one byte at a time", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "message4.bin");
    MessageStreamReader reader;
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        CHECK(reader.ready_count() == 0);
        CHECK(reader.partial_bytes() == i);
        REQUIRE(reader.feed(std::span<const std::byte>(bytes).subspan(i, 1)));
    }
    auto m = reader.take_message();
    REQUIRE(m);
    REQUIRE(*m);
    CHECK((*m)->entries.size() == 3);
    auto none = reader.take_message();
    REQUIRE(none);
    CHECK_FALSE(*none);
}

TEST_CASE("message: frames outlive the reader and decoded payloads point into them", "[shared]") {
    RR_REQUIRE_VECTOR(bytes, "message2.bin");
    SharedBytes frame;
    {
        MessageStreamReader reader;
        REQUIRE(reader.feed(bytes));
        frame = *reader.take_frame();
    }
    Message m = decode_message(frame).value();
    const auto& el1 = m.entries[1].elements[0];
    CHECK(el1.data.data() > frame.data());
    CHECK(el1.data.data() < frame.data() + frame.size());
}

TEST_CASE("message: after an error the stream reader stays failed", "[shared]") {
    RR_REQUIRE_VECTOR(good, "vec_connectiontest_v2.bin");
    MessageStreamReader reader;
    std::vector<std::byte> stream = good;
    stream.insert(stream.end(), {std::byte{'R'}, std::byte{'R'}, std::byte{'X'}});
    auto r = reader.feed(stream);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::ProtocolError);
    CHECK(reader.failed());
    REQUIRE(reader.error());
    CHECK(reader.error()->type == MessageErrorType::ProtocolError);
    CHECK_FALSE(reader.take_frame());  // not even the message completed before the error
    auto again = reader.feed(good);
    REQUIRE_FALSE(again);
    CHECK(again.error().type == MessageErrorType::ProtocolError);
    CHECK_FALSE(reader.take_message());
}

TEST_CASE("message: a frame that does not decode fails the stream reader", "[shared]") {
    RR_REQUIRE_VECTOR(good, "vec_connectiontest_v2.bin");
    auto bad = good;
    bad[8] = std::byte{3};  // version 3: framing is fine, decoding is not
    MessageStreamReader reader;
    REQUIRE(reader.feed(bad));
    REQUIRE(reader.feed(good));
    CHECK(reader.ready_count() == 2);
    auto m = reader.take_message();
    REQUIRE_FALSE(m);
    CHECK(m.error().type == MessageErrorType::ProtocolError);
    CHECK(reader.failed());
    CHECK_FALSE(reader.take_message());
    CHECK_FALSE(reader.feed(good));
}

TEST_CASE("message: the stream reader's size limit can change between messages", "[shared]") {
    RR_REQUIRE_VECTOR(big, "message2.bin");  // 1118 bytes
    Limits limits;
    limits.max_message_size = 1000;
    MessageStreamReader reader(limits);
    CHECK(reader.max_message_size() == 1000);
    auto r = reader.feed(big);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::BufferLimitViolation);

    MessageStreamReader later(limits);
    REQUIRE(later.feed(std::span<const std::byte>(big).first(4)));
    later.set_max_message_size(2000);  // e.g. the session now exists (wire.md 6.4)
    REQUIRE(later.feed(std::span<const std::byte>(big).subspan(4)));
    auto m = later.take_message();
    REQUIRE(m);
    CHECK(*m);
}

TEST_CASE("message: encoded messages stream back through the reader") {
    Message m;
    m.version = 4;
    m.entries.resize(2);
    m.entries[0].entry_type = MessageEntryType::ConnectionTest;
    m.entries[1].entry_type = MessageEntryType::ConnectionTestRet;
    std::vector<std::byte> stream;
    REQUIRE(encode_message(m, stream));
    m.version = 2;
    REQUIRE(encode_message(m, stream));
    rr::test::for_each_split(stream, [&](Result<std::vector<Message>> r, std::size_t at) {
        INFO("split at " << at);
        REQUIRE(r);
        REQUIRE(r->size() == 2);
        CHECK((*r)[0].version == 4);
        CHECK((*r)[1].version == 2);
        CHECK((*r)[1].entries == m.entries);
    });
}

TEST_CASE("message: the stream reader's buffer grows with the bytes received, not with MessageSize") {
    std::vector<std::byte> preamble = {std::byte{'R'}, std::byte{'R'}, std::byte{'A'}, std::byte{'C'},
                                       std::byte{0x00}, std::byte{0x00}, std::byte{0xc0}, std::byte{0x00}};  // 12 MiB
    MessageStreamReader reader;
    REQUIRE(reader.feed(preamble));
    CHECK(reader.partial_bytes() == 8);
    CHECK(reader.partial_capacity() <= 64 * 1024);
    std::vector<std::byte> chunk(100 * 1024, std::byte{0});
    for (int i = 0; i < 3; ++i) {
        REQUIRE(reader.feed(chunk));
        CHECK(reader.partial_bytes() == 8 + (i + 1) * chunk.size());
        CHECK(reader.partial_capacity() >= reader.partial_bytes());
        CHECK(reader.partial_capacity() <= 2 * reader.partial_bytes());
    }
    CHECK(reader.ready_count() == 0);
    // Once a quarter of the message is here, the buffer takes the whole MessageSize at once.
    std::vector<std::byte> mib = {std::byte{'R'}, std::byte{'R'}, std::byte{'A'}, std::byte{'C'},
                                  std::byte{0x00}, std::byte{0x00}, std::byte{0x10}, std::byte{0x00}};  // 1 MiB
    MessageStreamReader r1;
    REQUIRE(r1.feed(mib));
    std::vector<std::byte> piece(64 * 1024, std::byte{0});
    for (int i = 0; i < 3; ++i) {
        REQUIRE(r1.feed(piece));
        CHECK(r1.partial_capacity() <= 2 * r1.partial_bytes());
    }
    REQUIRE(r1.feed(piece));  // 256 KiB + 8 bytes: over a quarter
    CHECK(r1.partial_capacity() == 1024 * 1024);
    CHECK(r1.partial_capacity() <= 4 * r1.partial_bytes());
    // Small messages share one buffer of kReusedFrameBytes; larger ones up to 64 KiB get their own size.
    std::vector<std::byte> small = {std::byte{'R'}, std::byte{'R'}, std::byte{'A'}, std::byte{'C'},
                                    std::byte{20},  std::byte{0},   std::byte{0},   std::byte{0}};
    MessageStreamReader r2;
    REQUIRE(r2.feed(small));
    CHECK(r2.partial_capacity() == MessageStreamReader::kReusedFrameBytes);
    std::vector<std::byte> medium = {std::byte{'R'}, std::byte{'R'}, std::byte{'A'}, std::byte{'C'},
                                     std::byte{0xe8}, std::byte{0x03}, std::byte{0},  std::byte{0}};  // 1,000
    MessageStreamReader r3;
    REQUIRE(r3.feed(medium));
    CHECK(r3.partial_capacity() == 1000);
}

TEST_CASE("message: the stream reader reuses a small frame's buffer only once nothing holds it") {
    // Two different small messages (a ping and a Nop-sized call) and one over kReusedFrameBytes.
    Message a;
    a.entries.emplace_back().entry_type = MessageEntryType::ConnectionTest;
    Message b;
    b.version = 4;
    auto& e = b.entries.emplace_back();
    e.entry_type = MessageEntryType::FunctionCallReq;
    e.service_path = "bench";
    e.member_name = "Nop";
    e.request_id = 7;
    MessageElement value;  // decoded, its payload points into the frame
    value.name = "value";
    value.type = DataTypes::int32_t;
    value.data = SharedBytes::copy_of("\x01\x02\x03\x04", 4);
    e.elements.push_back(value);
    Message big = b;
    big.entries[0].metadata.assign(2 * MessageStreamReader::kReusedFrameBytes, 'm');
    auto wire = [](const Message& m) {
        auto f = encode_message(m);
        REQUIRE(f);
        return std::vector<std::byte>(f->bytes().begin(), f->bytes().end());
    };
    const auto wa = wire(a), wb = wire(b), wbig = wire(big);
    REQUIRE(wa.size() <= MessageStreamReader::kReusedFrameBytes);
    REQUIRE(wb.size() <= MessageStreamReader::kReusedFrameBytes);

    MessageStreamReader reader;
    REQUIRE(reader.feed(wa));
    auto first = reader.take_frame();
    REQUIRE(first);
    const std::byte* first_buffer = first->data();
    // Still held: the next message gets another buffer, and the held frame keeps its bytes.
    REQUIRE(reader.feed(wb));
    auto second = reader.take_frame();
    REQUIRE(second);
    CHECK(second->data() != first_buffer);
    CHECK(bytes_of(*first) == wa);
    CHECK(bytes_of(*second) == wb);
    // Released (with a decoded message that pointed into it): its buffer is reused.
    {
        auto decoded = decode_message(*second, Limits{});
        REQUIRE(decoded);
        const std::byte* second_buffer = second->data();
        second.reset();
        REQUIRE(reader.feed(wa));
        auto third = reader.take_frame();  // `decoded` still holds the second buffer
        REQUIRE(third);
        CHECK(third->data() != second_buffer);
        CHECK(decoded->entries[0].member_name == "Nop");
        first.reset();
        third.reset();
    }
    REQUIRE(reader.feed(wb));
    auto fourth = reader.take_frame();
    REQUIRE(fourth);
    CHECK(bytes_of(*fourth) == wb);
    const std::byte* reused = fourth->data();
    fourth.reset();
    // Two messages in one read: the first still waits in the reader, so the second gets another buffer.
    std::vector<std::byte> both = wa;
    both.insert(both.end(), wb.begin(), wb.end());
    REQUIRE(reader.feed(both));
    auto fifth = reader.take_frame();
    auto sixth = reader.take_frame();
    REQUIRE(fifth);
    REQUIRE(sixth);
    CHECK(fifth->data() == reused);
    CHECK(sixth->data() != reused);
    CHECK(bytes_of(*fifth) == wa);
    CHECK(bytes_of(*sixth) == wb);
    // A message over kReusedFrameBytes never takes the shared buffer.
    fifth.reset();
    sixth.reset();
    REQUIRE(reader.feed(wbig));
    auto large = reader.take_frame();
    REQUIRE(large);
    CHECK(bytes_of(*large) == wbig);
}

TEST_CASE("message: the rest of a large message is read in place through read_space") {
    // Two messages back to back: a 1 MiB one (its bytes a pattern) and a small one after it.
    Message big;
    big.version = 4;
    auto& e = big.entries.emplace_back();
    e.entry_type = MessageEntryType::WirePacket;
    MessageElement value;
    value.name = "value";
    value.type = DataTypes::uint8_t;
    std::vector<std::byte> payload(1 << 20);
    for (std::size_t i = 0; i < payload.size(); ++i) payload[i] = static_cast<std::byte>(i * 7 & 0xff);
    value.data = SharedBytes::adopt(std::move(payload));
    e.elements.push_back(value);
    Message small;
    small.entries.emplace_back().entry_type = MessageEntryType::ConnectionTest;
    std::vector<std::byte> stream;
    REQUIRE(encode_message(big, stream));
    const std::size_t big_size = stream.size();
    REQUIRE(encode_message(small, stream));

    MessageStreamReader reader;
    CHECK(reader.read_space().empty());  // nothing begun: the host's own buffer
    std::size_t at = 0;
    std::size_t in_place = 0;
    auto feed_normal = [&](std::size_t n) {
        REQUIRE(reader.feed(std::span<const std::byte>(stream).subspan(at, n)));
        at += n;
    };
    feed_normal(1000);  // the preamble and a first piece through the host's buffer
    while (at < stream.size()) {
        auto space = reader.read_space();
        if (space.empty()) {
            feed_normal(std::min<std::size_t>(4096, stream.size() - at));
            continue;
        }
        // The span never reaches past the large message, and the buffer stays within 4 × what arrived.
        CHECK(at + space.size() <= big_size);
        CHECK(space.size() >= MessageStreamReader::kDirectReadMinBytes);
        CHECK(reader.partial_capacity() <= std::max<std::size_t>(64 * 1024, 4 * reader.partial_bytes()));
        // A socket read of up to 50,000 bytes into the span, then the same bytes fed.
        const std::size_t n = std::min<std::size_t>(space.size(), 50'000);
        std::copy_n(stream.begin() + static_cast<std::ptrdiff_t>(at), n, space.begin());
        REQUIRE(reader.feed(space.first(n)));
        at += n;
        in_place += n;
    }
    CHECK(in_place > big_size / 2);
    REQUIRE(reader.ready_count() == 2);
    auto first = reader.take_frame();
    REQUIRE(first);
    CHECK(std::equal(first->bytes().begin(), first->bytes().end(), stream.begin(),
                     stream.begin() + static_cast<std::ptrdiff_t>(big_size)));
    auto decoded = decode_message(*first, Limits{});
    REQUIRE(decoded);
    CHECK(decoded->entries == big.entries);
    auto second = reader.take_frame();
    REQUIRE(second);
    CHECK(second->size() == stream.size() - big_size);
    CHECK(reader.read_space().empty());
    CHECK(reader.partial_bytes() == 0);
}

TEST_CASE("message: read_space offers nothing for small messages or a failed reader") {
    std::vector<std::byte> medium = {std::byte{'R'}, std::byte{'R'}, std::byte{'A'}, std::byte{'C'},
                                     std::byte{0xe8}, std::byte{0x03}, std::byte{0},  std::byte{0}};  // 1,000
    MessageStreamReader r;
    REQUIRE(r.feed(medium));
    CHECK(r.read_space().empty());  // in its final buffer already, through the host's reads
    std::vector<std::byte> mib = {std::byte{'R'}, std::byte{'R'}, std::byte{'A'}, std::byte{'C'},
                                  std::byte{0x00}, std::byte{0x00}, std::byte{0x10}, std::byte{0x00}};  // 1 MiB
    MessageStreamReader big;
    REQUIRE(big.feed(mib));
    CHECK_FALSE(big.read_space().empty());
    CHECK(big.partial_capacity() <= 64 * 1024);  // asking for space does not allocate the whole message
    std::vector<std::byte> bad = {std::byte{'X'}};
    MessageStreamReader failed;
    CHECK_FALSE(failed.feed(bad));
    CHECK(failed.read_space().empty());
}
