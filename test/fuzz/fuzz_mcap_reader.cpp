// libFuzzer target for the MCAP reader (core/mcap, issue 44): the input is a whole file. Invariants
// beyond "no crash, leak, hang or unbounded allocation" (small ReaderLimits):
//  - every error message names MCAP ("mcap: ..."), and once a MessageIterator failed it stays failed;
//  - every message yielded is on a channel of summary(); an indexed read yields log_time in order;
//  - a linear read (no index) yields as many messages as open() counted in its statistics;
//  - what reads back writes again with McapWriter and reads back equal (same messages, sorted by time).
// Seeds: test/fuzz/seeds/fuzz_mcap_reader (files written by rr_mcap_tool and by the Python and
// TypeScript reference writers, some cut off, test/mcap/mcap_interop.py describes them; and the
// crafted_*.mcap of test/record/crafted_mcap.py: Chunk Index records naming one 500 MiB chunk 16
// times, a chunk larger than the memory limit, an index understating it, a chunk announcing more than
// its data holds).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "core/mcap/mcap_reader.hpp"
#include "core/mcap/mcap_writer.hpp"

namespace {

using namespace rr;
using namespace rr::mcap;

void check(bool ok) {
    if (!ok) std::abort();
}

bool names_mcap(const RRError& e) { return e.message.rfind("mcap: ", 0) == 0; }

ReaderLimits small_limits() {
    ReaderLimits l;
    l.max_record_bytes = 1 << 20;
    l.max_chunk_uncompressed_bytes = 4 << 20;
    l.max_summary_bytes = 1 << 20;
    l.max_memory_bytes = 16 << 20;
    return l;
}

// All messages, or nullopt after an error (which must stay).
std::optional<std::vector<Message>> read_all(McapReader& reader, MessageQuery query = {}) {
    auto it = reader.messages(std::move(query));
    std::vector<Message> out;
    for (std::size_t n = 0; n < 1'000'000; ++n) {
        auto m = it.next();
        if (!m) {
            check(names_mcap(m.error()));
            check(!it.next().ok());
            return std::nullopt;
        }
        if (!*m) return out;
        check(reader.summary().channels.count((*m)->channel_id) == 1);
        out.push_back(std::move(**m));
    }
    std::abort();  // more messages than a fuzz input can hold: a loop
}

auto by_time(const Message& m) { return std::tie(m.log_time, m.channel_id, m.sequence, m.publish_time, m.data); }

void rewrite_and_compare(const McapReader& reader, std::vector<Message> messages) {
    std::vector<std::byte> file;
    VectorSink sink(file);
    WriterOptions options;
    options.chunk_size = 512;
    McapWriter w(sink, options);
    check(w.open().ok());
    std::map<std::uint16_t, std::uint16_t> schema_ids, channel_ids;
    for (const auto& [id, s] : reader.summary().schemas) schema_ids[id] = *w.add_schema(s.name, s.encoding, s.data);
    for (const auto& [id, c] : reader.summary().channels) {
        auto schema = schema_ids.count(c.schema_id) ? schema_ids[c.schema_id] : 0;
        channel_ids[id] = *w.add_channel(schema, c.topic, c.message_encoding, c.metadata);
    }
    for (auto& m : messages) {
        m.channel_id = channel_ids.at(m.channel_id);
        check(w.write({m.channel_id, m.sequence, m.log_time, m.publish_time, m.data}).ok());
    }
    check(w.close().ok());

    SpanSource source(file);
    auto again = McapReader::open(source);
    check(again.ok());
    check(again->indexed() || messages.empty());
    auto got = read_all(*again);
    check(got.has_value());
    auto order = [](const Message& a, const Message& b) { return by_time(a) < by_time(b); };
    std::sort(messages.begin(), messages.end(), order);
    std::sort(got->begin(), got->end(), order);
    check(*got == messages);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    SpanSource source(std::span(reinterpret_cast<const std::byte*>(data), size));
    auto reader = McapReader::open(source, small_limits());
    if (!reader) {
        check(names_mcap(reader.error()));
        return 0;
    }
    auto messages = read_all(*reader);
    if (!messages) return 0;
    if (reader->indexed()) {
        check(std::is_sorted(messages->begin(), messages->end(),
                             [](const Message& a, const Message& b) { return a.log_time < b.log_time; }));
    } else {
        check(messages->size() == reader->summary().statistics.message_count);
    }
    // A seek: the second half of the time range, the first channel only.
    if (!messages->empty() && !reader->summary().channels.empty()) {
        MessageQuery q;
        q.start_time = reader->summary().statistics.message_start_time / 2 + reader->summary().statistics.message_end_time / 2;
        q.channels = std::set<std::uint16_t>{reader->summary().channels.begin()->first};
        if (auto some = read_all(*reader, q)) {
            for (const auto& m : *some) check(m.log_time >= q.start_time && q.channels->count(m.channel_id));
        }
    }
    rewrite_and_compare(*reader, std::move(*messages));
    return 0;
}
