#include <catch2/catch.hpp>

#include <algorithm>

#include "core/codec/endian.hpp"
#include "core/mcap/mcap_test_files.hpp"

using namespace rr;
using namespace rr::mcap;
using namespace rr::mcap::test;

namespace {

std::vector<std::byte> sample_file(Compression compression, std::size_t chunk_size, std::uint32_t count,
                                   std::vector<Message>* written = nullptr) {
    std::vector<std::byte> file;
    VectorSink sink(file);
    WriterOptions options;
    options.compression = compression;
    options.chunk_size = chunk_size;
    McapWriter w(sink, options);
    auto msgs = write_sample(w, count);
    REQUIRE(w.close());
    if (written) *written = std::move(msgs);
    return file;
}

// Opens and reads everything; returns the error message, or "" when all went well.
std::string read_all(std::span<const std::byte> bytes, std::size_t* messages = nullptr) {
    SpanSource source(bytes);
    auto reader = McapReader::open(source);
    if (!reader) return reader.error().message;
    auto it = reader->messages();
    std::size_t n = 0;
    for (;;) {
        auto m = it.next();
        if (!m) return m.error().message;
        if (!*m) break;
        ++n;
    }
    if (messages) *messages = n;
    return "";
}

}  // namespace

TEST_CASE("mcap: seek by time yields the chosen channels' messages from t on, in log-time order") {
    std::vector<std::byte> file;
    VectorSink sink(file);
    WriterOptions options;
    options.chunk_size = 1 << 20;
    McapWriter w(sink, options);
    REQUIRE(w.open());
    auto a = *w.add_channel(0, "a", "json");
    auto b = *w.add_channel(0, "b", "json");
    std::vector<Message> written;
    // Three chunks whose time ranges overlap: 100..190, 50..140, 300..390.
    for (std::uint64_t base : {100, 50, 300}) {
        for (std::uint32_t i = 0; i < 10; ++i) {
            Message m{static_cast<std::uint16_t>(i % 3 ? a : b), i, base + 10 * i, base + 10 * i, payload(a, i)};
            REQUIRE(w.write({m.channel_id, m.sequence, m.log_time, m.publish_time, m.data}));
            written.push_back(m);
        }
        REQUIRE(w.flush());
    }
    REQUIRE(w.close());

    SpanSource source(file);
    auto reader = McapReader::open(source);
    REQUIRE(reader);
    REQUIRE(reader->summary().chunk_indexes.size() == 3);

    MessageQuery q;
    q.start_time = 120;
    q.end_time = 350;
    q.channels = std::set<std::uint16_t>{a};
    std::vector<Message> expected;
    for (const auto& m : written)
        if (m.channel_id == a && m.log_time >= 120 && m.log_time < 350) expected.push_back(m);
    std::stable_sort(expected.begin(), expected.end(),
                     [](const Message& x, const Message& y) { return x.log_time < y.log_time; });
    auto got = drain(reader->messages(q));
    CHECK(got == expected);

    // All of it: sorted by log time, every message once.
    auto all = drain(reader->messages());
    CHECK(all.size() == written.size());
    CHECK(std::is_sorted(all.begin(), all.end(), [](const Message& x, const Message& y) { return x.log_time < y.log_time; }));

    // A channel filter excludes chunks without that channel (message_index_offsets), and still works.
    MessageQuery only_b;
    only_b.channels = std::set<std::uint16_t>{b};
    for (const auto& m : drain(reader->messages(only_b))) CHECK(m.channel_id == b);
}

TEST_CASE("mcap: the default query includes messages at log_time 0 and UINT64_MAX") {
    std::vector<std::byte> file;
    VectorSink sink(file);
    McapWriter w(sink);
    REQUIRE(w.open());
    auto ch = *w.add_channel(0, "t", "json");
    std::vector<std::byte> data(1);
    REQUIRE(w.write({ch, 0, UINT64_MAX, UINT64_MAX, data}));
    REQUIRE(w.write({ch, 1, 0, 0, data}));
    REQUIRE(w.close());
    SpanSource source(file);
    auto reader = McapReader::open(source);
    REQUIRE(reader);
    auto all = drain(reader->messages());
    REQUIRE(all.size() == 2);
    CHECK(all[0].log_time == 0);
    CHECK(all[1].log_time == UINT64_MAX);
    MessageQuery q;
    q.end_time = UINT64_MAX;
    CHECK(drain(reader->messages(q)).size() == 1);  // exclusive
}

TEST_CASE("mcap: a chunk CRC mismatch is reported with the chunk's offset") {
    auto file = sample_file(Compression::None, 1 << 20, 20);
    // Flip one byte of a message payload inside the (uncompressed) chunk.
    auto needle = bytes_of("\"i\":7,");
    auto hit = std::search(file.begin(), file.end(), needle.begin(), needle.end());
    REQUIRE(hit != file.end());
    hit[4] = static_cast<std::byte>('8');

    SpanSource source(file);
    auto reader = McapReader::open(source);
    REQUIRE(reader);  // the summary is intact
    auto it = reader->messages();
    auto m = it.next();
    REQUIRE_FALSE(m);
    CHECK(m.error().type == MessageErrorType::DataSerializationError);
    CHECK_THAT(m.error().message, Catch::Matches("mcap: Chunk at offset \\d+: uncompressed_crc mismatch .*"));
    CHECK_FALSE(it.next());  // the error stays
}

TEST_CASE("mcap: a summary CRC mismatch fails open()") {
    auto file = sample_file(Compression::Zstd, 1 << 20, 20);
    // A byte of the Summary Offset records just before the footer.
    file[file.size() - 8 - 29 - 5] ^= std::byte{0x01};
    SpanSource source(file);
    auto reader = McapReader::open(source);
    REQUIRE_FALSE(reader);
    CHECK_THAT(reader.error().message, Catch::Contains("summary_crc mismatch"));
}

TEST_CASE("mcap: a file cut off mid-chunk reads up to its last complete chunk") {
    std::vector<std::byte> file;
    VectorSink sink(file);
    McapWriter w(sink);  // 1 MiB chunks: only flush() closes one here
    auto first = write_sample(w, 100);
    REQUIRE(w.flush());
    const auto after_first = file.size();
    // Payloads that do not compress, so the chunk is much longer than its message indexes.
    std::uint32_t x = 12345;
    std::vector<std::byte> payload_bytes(300);
    for (std::uint32_t i = 0; i < 100; ++i) {
        for (auto& b : payload_bytes) b = static_cast<std::byte>((x = x * 1103515245u + 12345u) >> 24);
        REQUIRE(w.write({0, i, 5000 + i, 5000 + i, payload_bytes}));
    }
    REQUIRE(w.flush());
    const auto after_second = file.size();
    // A writer killed here leaves the file as it is: no summary, no footer.

    SECTION("cut inside the second chunk") {
        std::span<const std::byte> cut(file.data(), (after_first + after_second) / 2);
        SpanSource source(cut);
        auto reader = McapReader::open(source);
        REQUIRE(reader);
        CHECK_FALSE(reader->indexed());
        REQUIRE(reader->truncated());
        CHECK_THAT(*reader->truncated(), Catch::Contains("file ends inside Chunk at offset"));
        CHECK(reader->summary().channels.size() == 2);
        CHECK(reader->summary().statistics.message_count == 100);
        CHECK(drain(reader->messages()) == first);
    }
    SECTION("cut at a chunk boundary") {
        SpanSource source(file);
        auto reader = McapReader::open(source);
        REQUIRE(reader);
        REQUIRE(reader->truncated());
        CHECK_THAT(*reader->truncated(), Catch::Contains("without a DataEnd"));
        CHECK(drain(reader->messages()).size() == 200);
    }
}

TEST_CASE("mcap: every prefix and every flipped byte of a file gives messages or a clear error, never a crash") {
    std::vector<Message> written;
    auto file = sample_file(Compression::Zstd, 200, 14, &written);
    std::size_t complete_reads = 0;
    for (std::size_t n = 0; n <= file.size(); ++n) {
        std::size_t count = 0;
        auto error = read_all(std::span(file.data(), n), &count);
        if (error.empty()) {
            ++complete_reads;
            CHECK(count <= written.size());
        } else {
            CHECK(error.rfind("mcap: ", 0) == 0);
        }
    }
    CHECK(complete_reads > file.size() / 2);  // cut files beyond the header read
    for (std::size_t i = 0; i < file.size(); ++i) {
        auto copy = file;
        copy[i] ^= std::byte{0xA5};
        auto error = read_all(copy);
        if (!error.empty()) CHECK(error.rfind("mcap: ", 0) == 0);
    }
}

TEST_CASE("mcap: limits stop oversized chunks and records before allocating") {
    auto file = sample_file(Compression::Zstd, 4096, 200);
    ReaderLimits limits;
    limits.max_chunk_uncompressed_bytes = 1000;
    SpanSource source(file);
    auto reader = McapReader::open(source, limits);
    REQUIRE(reader);  // indexed: chunks are read on demand
    auto m = reader->messages().next();
    REQUIRE_FALSE(m);
    CHECK(m.error().type == MessageErrorType::BufferLimitViolation);

    // Linear (footer cut off): the same check fires in open().
    std::span<const std::byte> cut(file.data(), file.size() - 10);
    SpanSource cut_source(cut);
    auto linear = McapReader::open(cut_source, limits);
    REQUIRE_FALSE(linear);
    CHECK(linear.error().type == MessageErrorType::BufferLimitViolation);

    // A record claiming 2^60 bytes in a file of a few: truncation, not an allocation.
    const auto header_len = load_le<std::uint64_t>(file.data() + 9);
    std::vector<std::byte> huge(file.begin(), file.begin() + 8 + 9 + static_cast<std::ptrdiff_t>(header_len));
    huge.push_back(std::byte{0x05});
    for (int i = 0; i < 8; ++i) huge.push_back(i == 7 ? std::byte{0x10} : std::byte{0});
    huge.resize(huge.size() + 64);
    SpanSource huge_source(huge);
    auto claimed = McapReader::open(huge_source);
    REQUIRE(claimed);
    CHECK_THAT(claimed->truncated().value_or(""), Catch::Contains("file ends inside Message"));
    SpanSource bad_magic(std::span(file.data() + 1, file.size() - 1));
    auto not_mcap = McapReader::open(bad_magic);
    REQUIRE_FALSE(not_mcap);
    CHECK_THAT(not_mcap.error().message, Catch::Contains("not an MCAP file"));
}
