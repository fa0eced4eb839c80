// Stream framing: messages in any split, frames as owned buffers, limits before allocation, and a
// failed reader that stays failed.
#include <catch2/catch.hpp>

#include "core/message/for_each_split.hpp"
#include "core/message/message_stream_reader.hpp"
#include "core/message/message_writer.hpp"
#include "core/message/test_vectors.hpp"

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
    // Small messages get buffers of their own size.
    std::vector<std::byte> small = {std::byte{'R'}, std::byte{'R'}, std::byte{'A'}, std::byte{'C'},
                                    std::byte{20},  std::byte{0},   std::byte{0},   std::byte{0}};
    MessageStreamReader r2;
    REQUIRE(r2.feed(small));
    CHECK(r2.partial_capacity() == 20);
}
