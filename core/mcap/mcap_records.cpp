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

}  // namespace rr::mcap
