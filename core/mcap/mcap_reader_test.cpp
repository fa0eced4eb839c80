#include <catch2/catch.hpp>

#include <zstd.h>

#include <algorithm>
#include <cstdio>

#include "base/codec/endian.hpp"
#include "core/mcap/mcap_record_codec.hpp"
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

// --- crafted files (issue 52): memory a file can make the reader take ------------------------------

namespace {

// `file` (closed by McapWriter) with its summary replaced by its schemas, its channels and `indexes`.
std::vector<std::byte> with_chunk_indexes(const std::vector<std::byte>& file, const std::vector<ChunkIndex>& indexes) {
    SpanSource source(file);
    auto reader = McapReader::open(source);
    REQUIRE(reader);
    const std::size_t footer_at = file.size() - 8 - detail::kFooterRecordBytes;
    const auto summary_start = load_le<std::uint64_t>(file.data() + footer_at + detail::kRecordPrefixBytes);
    std::vector<std::byte> out(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(summary_start));
    for (const auto& [id, s] : reader->summary().schemas) detail::encode_schema(out, s);
    for (const auto& [id, c] : reader->summary().channels) detail::encode_channel(out, c);
    for (const auto& ci : indexes) detail::encode_chunk_index(out, ci);
    detail::encode_footer_prefix(out, summary_start, 0);
    for (int i = 0; i < 4; ++i) out.push_back(std::byte{0});  // summary_crc 0: not checked
    detail::append_magic(out);
    return out;
}

// One message of `bytes` zeros in one zstd chunk (a few KiB on disk), closed.
std::vector<std::byte> zeros_file(std::size_t bytes) {
    std::vector<std::byte> file;
    VectorSink sink(file);
    WriterOptions options;
    options.chunk_size = bytes + 4096;
    McapWriter w(sink, options);
    REQUIRE(w.open());
    auto ch = *w.add_channel(0, "zeros", "json");
    std::vector<std::byte> data(bytes);
    REQUIRE(w.write({ch, 0, 100, 100, data}));
    REQUIRE(w.close());
    return file;
}

// The peak resident memory of this process, bytes (Linux; 0 elsewhere), and its reset.
std::uint64_t peak_rss() {
    std::FILE* f = std::fopen("/proc/self/status", "r");
    if (!f) return 0;
    char line[256];
    std::uint64_t kb = 0;
    while (std::fgets(line, sizeof line, f))
        if (std::sscanf(line, "VmHWM: %llu kB", reinterpret_cast<unsigned long long*>(&kb)) == 1) break;
    std::fclose(f);
    return kb * 1024;
}
bool reset_peak_rss() {
    std::FILE* f = std::fopen("/proc/self/clear_refs", "w");
    if (!f) return false;
    const bool ok = std::fputs("5", f) >= 0;
    return std::fclose(f) == 0 && ok;
}

}  // namespace

TEST_CASE("mcap: Chunk Index records naming one chunk twice, or overlapping chunks, are refused at open") {
    auto file = sample_file(Compression::Zstd, 1 << 20, 50);
    SpanSource source(file);
    auto reader = McapReader::open(source);
    REQUIRE(reader);
    REQUIRE(reader->summary().chunk_indexes.size() == 1);
    const auto ci = reader->summary().chunk_indexes[0];

    // 16 indexes of one chunk (issue 52: each was decoded again, 16 times the chunk's memory).
    auto dup = with_chunk_indexes(file, std::vector<ChunkIndex>(16, ci));
    SpanSource dup_source(dup);
    auto d = McapReader::open(dup_source);
    REQUIRE_FALSE(d);
    CHECK(d.error().type == MessageErrorType::DataSerializationError);
    CHECK_THAT(d.error().message, Catch::Matches("mcap: ChunkIndex at offset \\d+: a second index of the chunk at offset " +
                                                 std::to_string(ci.chunk_start_offset) + " .*"));

    // An index pointing inside another chunk's bytes.
    auto inner = ci;
    inner.chunk_start_offset += 20;
    inner.chunk_length -= 20;
    auto overlap = with_chunk_indexes(file, {ci, inner});
    SpanSource overlap_source(overlap);
    auto o = McapReader::open(overlap_source);
    REQUIRE_FALSE(o);
    CHECK_THAT(o.error().message, Catch::Contains("begins inside the chunk at offset " + std::to_string(ci.chunk_start_offset)));

    // The file with its one index still reads (the rebuilt summary itself is fine).
    auto once = with_chunk_indexes(file, {ci});
    CHECK(read_all(once).empty());
}

TEST_CASE("mcap: a chunk larger than the memory limit is refused, at open when its index says so") {
    auto file = zeros_file(8 << 20);  // 8 MiB of zeros, a few KiB of zstd
    CHECK(file.size() < 64 * 1024);
    ReaderLimits limits;
    limits.max_memory_bytes = 4 << 20;

    SpanSource source(file);
    auto r = McapReader::open(source, limits);
    REQUIRE_FALSE(r);
    CHECK(r.error().type == MessageErrorType::BufferLimitViolation);
    CHECK_THAT(r.error().message, Catch::Contains("can never be read within the reader's memory limit of 4194304 bytes"));

    // An index that understates the chunk: open() passes, reading the chunk fails before decompressing.
    SpanSource honest(file);
    auto ci = McapReader::open(honest)->summary().chunk_indexes.at(0);
    ci.uncompressed_size = 1000;
    auto lying = with_chunk_indexes(file, {ci});
    SpanSource lying_source(lying);
    auto l = McapReader::open(lying_source, limits);
    REQUIRE(l);
    const auto summary_memory = l->memory_bytes();
    CHECK(summary_memory < 64 * 1024);
    auto it = l->messages();
    auto m = it.next();
    REQUIRE_FALSE(m);
    CHECK(m.error().type == MessageErrorType::BufferLimitViolation);
    CHECK_THAT(m.error().message, Catch::Contains("Chunk at offset"));
    CHECK_THAT(m.error().message, Catch::Contains("its uncompressed records (83886"));
    CHECK(l->memory_bytes() == summary_memory);  // what the failed step took is given back

    // Linear (no summary): the scan in open() stops at the chunk.
    std::span<const std::byte> cut(file.data(), file.size() - 10);
    SpanSource cut_source(cut);
    auto c = McapReader::open(cut_source, limits);
    REQUIRE_FALSE(c);
    CHECK(c.error().type == MessageErrorType::BufferLimitViolation);

    // Within the limit it reads, and the iterator's memory goes back when it is done.
    limits.max_memory_bytes = 32 << 20;
    SpanSource ok_source(file);
    auto ok = McapReader::open(ok_source, limits);
    REQUIRE(ok);
    const auto before = ok->memory_bytes();
    {
        auto msgs = drain(ok->messages());
        REQUIRE(msgs.size() == 1);
        CHECK(msgs[0].data.size() == (8u << 20));
    }
    CHECK(ok->memory_bytes() == before);
}

TEST_CASE("mcap: overlapping chunks are held at once only within the memory limit") {
    // Ten chunks whose time ranges all overlap: an indexed read (log-time order) holds more and more of
    // them while it yields the early messages; their messages together pass a 2 MiB limit.
    std::vector<std::byte> file;
    VectorSink sink(file);
    WriterOptions options;
    options.chunk_size = 1 << 20;
    McapWriter w(sink, options);
    REQUIRE(w.open());
    auto ch = *w.add_channel(0, "t", "json");
    std::vector<std::byte> data(300 * 1024, std::byte{7});
    for (std::uint32_t chunk = 0; chunk < 10; ++chunk) {
        REQUIRE(w.write({ch, chunk, 1000 + chunk, 1000 + chunk, data}));
        REQUIRE(w.write({ch, chunk, 5000 - chunk, 5000 - chunk, data}));
        REQUIRE(w.flush());
    }
    REQUIRE(w.close());
    ReaderLimits limits;
    limits.max_memory_bytes = 2 << 20;
    SpanSource source(file);
    auto reader = McapReader::open(source, limits);
    REQUIRE(reader);
    auto it = reader->messages();
    Result<std::optional<Message>> m = std::optional<Message>{};
    std::size_t n = 0;
    while ((m = it.next()) && *m) ++n;
    REQUIRE_FALSE(m);
    CHECK(m.error().type == MessageErrorType::BufferLimitViolation);
    CHECK_THAT(m.error().message, Catch::Contains("the messages waiting to be read"));
    CHECK(n < 10);
    // A limit that holds them all reads all 20.
    limits.max_memory_bytes = 16 << 20;
    SpanSource again(file);
    auto enough = McapReader::open(again, limits);
    REQUIRE(enough);
    CHECK(drain(enough->messages()).size() == 20);
}

TEST_CASE("mcap: a chunk's announced uncompressed size is not allocated before its data proves it") {
    // A chunk announcing 200 MiB (within the default limits) whose zstd frame, of unknown content size,
    // holds one small Message record.
    std::vector<std::byte> records;
    Channel channel{1, 0, "t", "json", {}};
    std::vector<std::byte> file;
    detail::append_magic(file);
    detail::encode_header(file, Header{"", "crafted"});
    detail::encode_channel(file, channel);
    std::vector<std::byte> payload(100, std::byte{1});
    detail::encode_message(records, 1, 0, 10, 10, payload);
    std::vector<std::byte> frame(ZSTD_compressBound(records.size()) + 64);
    ZSTD_CCtx* cctx = ZSTD_createCCtx();
    ZSTD_CCtx_setParameter(cctx, ZSTD_c_contentSizeFlag, 0);
    ZSTD_inBuffer in{records.data(), records.size(), 0};
    ZSTD_outBuffer out{frame.data(), frame.size(), 0};
    REQUIRE(ZSTD_compressStream2(cctx, &out, &in, ZSTD_e_end) == 0);  // no pledged size: none in the frame
    ZSTD_freeCCtx(cctx);
    frame.resize(out.pos);
    REQUIRE(ZSTD_getFrameContentSize(frame.data(), frame.size()) == ZSTD_CONTENTSIZE_UNKNOWN);
    const std::uint64_t announced = 200ull << 20;
    detail::encode_chunk_prefix(file, 10, 10, announced, 0, "zstd", frame.size());
    file.insert(file.end(), frame.begin(), frame.end());

    const bool measured = reset_peak_rss();
    const auto before = peak_rss();
    SpanSource source(file);
    auto reader = McapReader::open(source);  // linear: open() decodes the chunk
    const auto after = peak_rss();
    REQUIRE_FALSE(reader);
    CHECK(reader.error().type == MessageErrorType::DataSerializationError);
    CHECK_THAT(reader.error().message, Catch::Contains("zstd output is " + std::to_string(records.size()) +
                                                       " bytes, uncompressed_size says " + std::to_string(announced)));
    if (measured && before) {
        INFO("peak RSS before " << before << ", after " << after);
        CHECK(after - before < (32u << 20));
    }
}
