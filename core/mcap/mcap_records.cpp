#include "core/mcap/mcap_records.hpp"

#include <cstdio>

namespace rr::mcap {

std::string opcode_name(std::uint8_t opcode) {
    static constexpr const char* kNames[] = {
        "invalid",         "Header",     "Footer",         "Schema",   "Channel",
        "Message",         "Chunk",      "MessageIndex",   "ChunkIndex", "Attachment",
        "AttachmentIndex", "Statistics", "Metadata",       "MetadataIndex", "SummaryOffset",
        "DataEnd",
    };
    if (opcode >= 1 && opcode <= 0x0F) return kNames[opcode];
    char buf[24];
    std::snprintf(buf, sizeof buf, "%s(0x%02X)", opcode == 0 ? "invalid" : opcode >= 0x80 ? "private" : "reserved",
                  static_cast<unsigned>(opcode));
    return buf;
}

// A map or vector node of a few words, and the allocator's own overhead: an estimate, not a count.
constexpr std::size_t kNodeBytes = 64;

std::size_t memory_of(const Schema& s) noexcept { return sizeof(Schema) + kNodeBytes + s.name.size() + s.encoding.size() + s.data.size(); }

std::size_t memory_of(const Channel& c) noexcept {
    std::size_t n = sizeof(Channel) + kNodeBytes + c.topic.size() + c.message_encoding.size();
    for (const auto& [k, v] : c.metadata) n += kNodeBytes + k.size() + v.size();
    return n;
}

std::size_t memory_of(const ChunkIndex& i) noexcept {
    return sizeof(ChunkIndex) + i.compression.size() + kNodeBytes * i.message_index_offsets.size();
}

}  // namespace rr::mcap
