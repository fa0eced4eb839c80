#include "base/codec/byte_reader.hpp"

#include <string>

namespace rr {

// Error construction is kept out of line: it is the cold path.
Unexpected ByteReader::truncated(std::size_t wanted) const {
    return fail(MessageErrorType::ProtocolError, "truncated: need " + std::to_string(wanted) + " bytes at offset " +
                                                     std::to_string(pos_) + ", " + std::to_string(remaining()) +
                                                     " left");
}

Unexpected ByteReader::too_many(std::size_t count, std::size_t item_size) const {
    return fail(MessageErrorType::ProtocolError, "truncated: " + std::to_string(count) + " items of " +
                                                     std::to_string(item_size) + " bytes at offset " +
                                                     std::to_string(pos_) + ", " + std::to_string(remaining()) +
                                                     " bytes left");
}

}  // namespace rr
