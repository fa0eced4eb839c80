// rr_mcap_tool: writes the interop sample recording with our MCAP writer and dumps any MCAP file with our
// reader as JSON, for test/mcap/mcap_interop.py (the reference implementations do the same there).
//
// Usage:
//   rr_mcap_tool write-sample OUT [--compression zstd|none] [--chunk-size BYTES] [--count N]
//   rr_mcap_tool dump FILE [--start NS] [--topic T]...
// The sample (the same in mcap_interop.py and mcap_reference.mjs): a jsonschema schema, channel
// "sample/json" (json, with the schema and metadata) and "sample/rr" (robotraconteur, no schema); message i
// on sample/json when i is even, else sample/rr; sequence i/2; log_time T0 + i*1000003 ns; publish_time
// log_time - 7; data {"i":i} on sample/json, bytes (i+k)%256 for k < i%300 on sample/rr.
// dump prints {"header", "schemas" by name, "channels" by topic, "messages": [[topic, sequence,
// log_time, publish_time, hex data], ...] in the reader's order, "indexed", "truncated"}; times as strings.
// Exit status: 0, 1 on a reader or writer error (message on stderr), 2 on bad usage.
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/mcap/mcap_reader.hpp"
#include "core/mcap/mcap_writer.hpp"
#include "server/mcap/mcap_file.hpp"

using namespace rr;
using namespace rr::mcap;

namespace {

constexpr std::uint64_t kT0 = 1700000000000000000ull;

std::vector<std::byte> bytes_of(const std::string& s) {
    std::vector<std::byte> out(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) out[i] = static_cast<std::byte>(s[i]);
    return out;
}

std::string hex(std::span<const std::byte> b) {
    static const char* digits = "0123456789abcdef";
    std::string out;
    out.reserve(b.size() * 2);
    for (auto x : b) {
        out.push_back(digits[static_cast<unsigned>(x) >> 4]);
        out.push_back(digits[static_cast<unsigned>(x) & 15]);
    }
    return out;
}

int usage() {
    std::cerr << "usage: rr_mcap_tool write-sample OUT [--compression zstd|none] [--chunk-size BYTES] [--count N]\n"
                 "       rr_mcap_tool dump FILE [--start NS] [--topic T]...\n";
    return 2;
}

int error(const RRError& e) {
    std::cerr << "rr_mcap_tool: " << e.message << "\n";
    return 1;
}

int write_sample(const std::string& out, const std::vector<std::string>& args) {
    WriterOptions options;
    options.library = "rr_mcap_tool";
    std::uint32_t count = 200;
    for (std::size_t i = 0; i + 1 < args.size(); i += 2) {
        if (args[i] == "--compression") options.compression = args[i + 1] == "none" ? Compression::None : Compression::Zstd;
        else if (args[i] == "--chunk-size") options.chunk_size = std::stoull(args[i + 1]);
        else if (args[i] == "--count") count = static_cast<std::uint32_t>(std::stoul(args[i + 1]));
        else return usage();
    }
    auto sink = FileSink::create(out);
    if (!sink) return error(sink.error());
    McapWriter w(**sink, options);
    if (auto r = w.open(); !r) return error(r.error());
    auto schema = w.add_schema("experimental.sample.Sample", "jsonschema",
                               bytes_of(R"({"type":"object","properties":{"i":{"type":"integer"}}})"));
    if (!schema) return error(schema.error());
    auto json = w.add_channel(*schema, "sample/json", "json", {{"device", "sample"}, {"member", "json"}});
    if (!json) return error(json.error());
    auto rr = w.add_channel(0, "sample/rr", "robotraconteur");
    if (!rr) return error(rr.error());
    for (std::uint32_t i = 0; i < count; ++i) {
        std::vector<std::byte> data;
        if (i % 2 == 0) {
            data = bytes_of("{\"i\":" + std::to_string(i) + "}");
        } else {
            for (std::uint32_t k = 0; k < i % 300; ++k) data.push_back(static_cast<std::byte>((i + k) % 256));
        }
        std::uint64_t t = kT0 + std::uint64_t{i} * 1000003;
        if (auto r = w.write({i % 2 == 0 ? *json : *rr, i / 2, t, t - 7, data}); !r) return error(r.error());
    }
    if (auto r = w.close(); !r) return error(r.error());
    if (auto r = (*sink)->close(); !r) return error(r.error());
    return 0;
}

int dump(const std::string& path, const std::vector<std::string>& args) {
    MessageQuery query;
    std::set<std::string> topics;
    for (std::size_t i = 0; i + 1 < args.size(); i += 2) {
        if (args[i] == "--start") query.start_time = std::stoull(args[i + 1]);
        else if (args[i] == "--topic") topics.insert(args[i + 1]);
        else return usage();
    }
    auto source = FileSource::open(path);
    if (!source) return error(source.error());
    auto reader = McapReader::open(**source);
    if (!reader) return error(reader.error());
    const auto& summary = reader->summary();
    nlohmann::json out;
    out["header"] = {{"profile", reader->header().profile}, {"library", reader->header().library}};
    out["schemas"] = nlohmann::json::object();
    for (const auto& [id, s] : summary.schemas)
        out["schemas"][s.name] = {{"encoding", s.encoding}, {"data", hex(s.data)}};
    out["channels"] = nlohmann::json::object();
    for (const auto& [id, c] : summary.channels) {
        auto schema = summary.schemas.find(c.schema_id);
        out["channels"][c.topic] = {{"message_encoding", c.message_encoding},
                                    {"schema", schema == summary.schemas.end() ? "" : schema->second.name},
                                    {"metadata", c.metadata}};
        if (topics.count(c.topic)) {
            if (!query.channels) query.channels.emplace();
            query.channels->insert(id);
        }
    }
    if (!topics.empty() && !query.channels) query.channels.emplace();  // no such topic: nothing
    out["message_count"] = summary.statistics.message_count;
    out["indexed"] = reader->indexed();
    out["truncated"] = reader->truncated() ? nlohmann::json(*reader->truncated()) : nlohmann::json(nullptr);
    auto messages = nlohmann::json::array();
    auto it = reader->messages(query);
    for (;;) {
        auto m = it.next();
        if (!m) return error(m.error());
        if (!*m) break;
        const auto& msg = **m;
        messages.push_back({summary.channels.at(msg.channel_id).topic, msg.sequence, std::to_string(msg.log_time),
                            std::to_string(msg.publish_time), hex(msg.data)});
    }
    out["messages"] = std::move(messages);
    std::cout << out.dump() << "\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 3) return usage();
    std::string command = argv[1];
    std::vector<std::string> rest(argv + 3, argv + argc);
    try {
        if (command == "write-sample") return write_sample(argv[2], rest);
        if (command == "dump") return dump(argv[2], rest);
    } catch (const std::exception& e) {  // std::stoull on a bad number; a topic that is not UTF-8 in dump
        std::cerr << "rr_mcap_tool: " << e.what() << "\n";
        return 1;
    }
    return usage();
}
