#include <catch2/catch.hpp>

#include "core/mcap/mcap_test_files.hpp"

using namespace rr;
using namespace rr::mcap;
using namespace rr::mcap::test;

namespace {

// A sink that fails once `capacity` bytes have been written.
class FailingSink final : public Sink {
public:
    explicit FailingSink(std::size_t capacity) : capacity_(capacity) {}
    Result<void> write(std::span<const std::byte> bytes) override {
        if (written_ + bytes.size() > capacity_) return fail(MessageErrorType::IOError, "disk full");
        written_ += bytes.size();
        return {};
    }
    std::size_t flushes = 0;
    Result<void> flush() override {
        ++flushes;
        return {};
    }

private:
    std::size_t capacity_;
    std::size_t written_ = 0;
};

}  // namespace

TEST_CASE("mcap: a written file starts and ends with the magic and reads back exactly") {
    auto compression = GENERATE(Compression::Zstd, Compression::None);
    std::vector<std::byte> file;
    VectorSink sink(file);
    WriterOptions options;
    options.compression = compression;
    options.chunk_size = 4096;
    options.library = "mcap test";
    McapWriter w(sink, options);
    auto written = write_sample(w, 500);
    REQUIRE(w.close());
    CHECK(w.is_closed());
    CHECK(w.bytes_written() == file.size());
    REQUIRE(file.size() > 16);
    for (std::size_t i = 0; i < 8; ++i) {
        CHECK(static_cast<std::uint8_t>(file[i]) == kMagic[i]);
        CHECK(static_cast<std::uint8_t>(file[file.size() - 8 + i]) == kMagic[i]);
    }

    SpanSource source(file);
    auto reader = McapReader::open(source);
    REQUIRE(reader);
    CHECK(reader->indexed());
    CHECK_FALSE(reader->truncated());
    CHECK(reader->header() == Header{"", "mcap test"});
    const auto& summary = reader->summary();
    CHECK(summary.from_summary_section);
    REQUIRE(summary.schemas.size() == 1);
    CHECK(summary.schemas.at(1).encoding == "jsonschema");
    REQUIRE(summary.channels.size() == 2);
    CHECK(summary.channels.at(0).metadata == std::map<std::string, std::string>{{"device", "dev"}, {"member", "a"}});
    CHECK(summary.channels.at(1).schema_id == 0);
    CHECK(summary.channels.at(1).message_encoding == "robotraconteur");
    CHECK(summary.statistics.message_count == 500);
    CHECK(summary.statistics.channel_message_counts == std::map<std::uint16_t, std::uint64_t>{{0, 250}, {1, 250}});
    CHECK(summary.statistics.message_start_time == 1000);
    CHECK(summary.statistics.message_end_time == 1000 + 10 * 499);
    CHECK(summary.statistics.chunk_count == summary.chunk_indexes.size());
    CHECK(summary.chunk_indexes.size() > 3);
    for (const auto& ci : summary.chunk_indexes) {
        CHECK(ci.compression == (compression == Compression::Zstd ? "zstd" : ""));
        CHECK(ci.message_index_offsets.size() == 2);
    }
    CHECK(drain(reader->messages()) == written);
    CHECK(w.statistics() == summary.statistics);
}

TEST_CASE("mcap: chunks close at the size limit, and a message larger than a chunk gets one of its own") {
    std::vector<std::byte> file;
    VectorSink sink(file);
    WriterOptions options;
    options.chunk_size = 256;
    McapWriter w(sink, options);
    REQUIRE(w.open());
    auto ch = w.add_channel(0, "big", "robotraconteur");
    REQUIRE(ch);
    std::vector<std::byte> big(10000, std::byte{0x5A});
    std::vector<std::byte> small(10, std::byte{1});
    REQUIRE(w.write({*ch, 0, 5, 5, small}));
    CHECK(w.statistics().chunk_count == 0);  // the channel record and one message: under 256 bytes
    REQUIRE(w.write({*ch, 1, 6, 6, big}));
    CHECK(w.statistics().chunk_count == 1);  // full: written
    REQUIRE(w.write({*ch, 2, 7, 7, small}));
    REQUIRE(w.flush());  // explicit flush writes the partial chunk
    CHECK(w.statistics().chunk_count == 2);
    REQUIRE(w.flush());  // nothing open: no empty chunk
    CHECK(w.statistics().chunk_count == 2);
    REQUIRE(w.close());

    SpanSource source(file);
    auto reader = McapReader::open(source);
    REQUIRE(reader);
    const auto& ci = reader->summary().chunk_indexes;
    REQUIRE(ci.size() == 2);
    CHECK(ci[0].message_start_time == 5);
    CHECK(ci[0].message_end_time == 6);
    CHECK(ci[1].message_start_time == 7);
    auto got = drain(reader->messages());
    REQUIRE(got.size() == 3);
    CHECK(got[1].data == big);
}

TEST_CASE("mcap: schemas and channels flushed before any message go outside a chunk, so no chunk lacks messages") {
    // A chunk without messages has no Message Index and times 0: @mcap/core 2.0 (Lichtblick 1.10)
    // refuses to read such a file, and readers taking the chunk indexes' times start it at 1970.
    std::vector<std::byte> file;
    VectorSink sink(file);
    McapWriter w(sink);
    REQUIRE(w.open());
    const std::string text = "service example";
    auto schema = w.add_schema("example", "robotraconteur_servicedef", std::as_bytes(std::span(text)));
    REQUIRE(schema);
    auto ch = w.add_channel(*schema, "dev/wire", "robotraconteur");
    REQUIRE(ch);
    REQUIRE(w.flush());  // what a recording does at start, so a killed gateway's file has its channels
    CHECK(w.statistics().chunk_count == 0);
    const auto before_messages = file.size();
    std::vector<std::byte> data(8, std::byte{7});
    REQUIRE(w.write({*ch, 0, 1000, 1000, data}));
    auto late = w.add_channel(*schema, "dev/late", "robotraconteur");  // added after the last message
    REQUIRE(late);
    REQUIRE(w.flush());
    CHECK(w.statistics().chunk_count == 1);
    auto later = w.add_channel(*schema, "dev/later", "robotraconteur");
    REQUIRE(later);
    REQUIRE(w.close());
    CHECK(w.statistics().chunk_count == 1);

    SpanSource source(file);
    auto reader = McapReader::open(source);
    REQUIRE(reader);
    REQUIRE(reader->indexed());
    const auto& summary = reader->summary();
    REQUIRE(summary.chunk_indexes.size() == 1);
    CHECK(summary.chunk_indexes[0].message_start_time == 1000);
    CHECK(summary.chunk_indexes[0].message_index_length > 0);
    CHECK(summary.channels.size() == 3);
    CHECK(drain(reader->messages()).size() == 1);

    // Killed after the first flush: the channels are in the data section, read linearly.
    std::span<const std::byte> killed(file.data(), before_messages);
    SpanSource killed_source(killed);
    auto linear = McapReader::open(killed_source);
    REQUIRE(linear);
    CHECK_FALSE(linear->indexed());
    CHECK(linear->summary().schemas.size() == 1);
    CHECK(linear->summary().channels.size() == 1);
    CHECK(drain(linear->messages()).empty());
}

TEST_CASE("mcap: writer refuses calls out of order and unknown ids, and keeps the first sink error") {
    std::vector<std::byte> file;
    VectorSink sink(file);
    McapWriter w(sink);
    std::vector<std::byte> data(3);
    CHECK(w.write({0, 0, 0, 0, data}).error().type == MessageErrorType::InvalidState);
    REQUIRE(w.open());
    CHECK(w.add_channel(7, "t", "json").error().type == MessageErrorType::InvalidArgument);
    CHECK(w.write({0, 0, 0, 0, data}).error().type == MessageErrorType::InvalidArgument);
    REQUIRE(w.close());
    CHECK(w.write({0, 0, 0, 0, data}).error().type == MessageErrorType::InvalidState);
    CHECK(w.close().error().type == MessageErrorType::InvalidState);

    FailingSink small(200);
    WriterOptions options;
    options.chunk_size = 64;
    McapWriter f(small, options);
    REQUIRE(f.open());
    auto ch = f.add_channel(0, "t", "json");
    REQUIRE(ch);
    Result<void> r;
    std::vector<std::byte> payload(50);
    for (int i = 0; i < 20 && r; ++i) r = f.write({*ch, 0, 1, 1, payload});
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::IOError);
    CHECK(r.error().message == "disk full");
    auto again = f.write({*ch, 0, 1, 1, payload});
    CHECK(again.error().type == MessageErrorType::InvalidState);
    CHECK(again.error().message.find("disk full") != std::string::npos);
    CHECK_FALSE(f.is_open());
}

TEST_CASE("mcap: each completed chunk is flushed to the sink") {
    FailingSink sink(1 << 20);
    WriterOptions options;
    options.chunk_size = 512;
    McapWriter w(sink, options);
    write_sample(w, 100);
    auto chunks = w.statistics().chunk_count;
    CHECK(chunks > 2);
    CHECK(sink.flushes == chunks + 1);  // + the one after the header
}

TEST_CASE("mcap: the writer's summary memory grows by one chunk index a chunk, as counted") {
    std::vector<std::byte> file;
    VectorSink sink(file);
    McapWriter w(sink);
    REQUIRE(w.open());
    auto a = *w.add_channel(0, "a", "json", {{"k", "v"}});
    auto b = *w.add_channel(0, "b", "json");
    const auto channels_only = w.summary_memory_bytes();
    CHECK(channels_only > 0);
    std::vector<std::byte> data(10);
    std::size_t last = channels_only;
    for (std::uint32_t i = 0; i < 50; ++i) {
        REQUIRE(w.write({a, i, i, i, data}));
        REQUIRE(w.write({b, i, i, i, data}));
        REQUIRE(w.flush());  // one chunk
        CHECK(w.summary_memory_bytes() > last);
        last = w.summary_memory_bytes();
    }
    REQUIRE(w.close());
    SpanSource source(file);
    auto r = McapReader::open(source);
    REQUIRE(r);
    std::size_t expected = 0;
    for (const auto& [id, c] : r->summary().channels) expected += memory_of(c);
    for (const auto& ci : r->summary().chunk_indexes) expected += memory_of(ci);
    CHECK(r->summary().chunk_indexes.size() == 50);
    CHECK(w.summary_memory_bytes() == expected);
}
