#include "base/message/encoded_entry.hpp"

#include <string>

#include "base/message/message_writer.hpp"

namespace rr {

Result<std::span<const std::byte>> EncodedEntry::bytes(std::uint16_t version) const {
    if (version != 2 && version != 4)
        return fail(MessageErrorType::InvalidArgument, "unknown message version " + std::to_string(version));
    Encoding& e = version == 2 ? v2_ : v4_;
    std::call_once(e.once, [&] {
        if (auto ok = encode_entry(entry_, version, e.bytes); !ok) {
            e.bytes.clear();
            e.error = ok.error();
        }
    });
    if (e.error) return fail(*e.error);
    return std::span<const std::byte>(e.bytes);
}

Result<SharedBytes> EncodedEntry::shared_bytes(std::uint16_t version, std::size_t owned_from) const {
    auto span = bytes(version);
    if (!span) return span.take_error();
    if (span->size() < owned_from) return SharedBytes(nullptr, *span);
    return SharedBytes(weak_from_this().lock(), *span);
}

}  // namespace rr
