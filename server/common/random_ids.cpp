#include "server/common/random_ids.hpp"

#include <random>

namespace rr::server {

namespace {

std::mt19937& generator() {
    static thread_local std::mt19937 rng{std::random_device{}()};
    return rng;
}

}  // namespace

NodeID random_node_id() {
    auto& rng = generator();
    NodeID::Bytes b{};
    for (std::size_t i = 0; i < b.size(); i += 4) {
        const std::uint32_t v = rng();
        for (std::size_t k = 0; k < 4; ++k) b[i + k] = static_cast<std::byte>((v >> (8 * k)) & 0xFF);
    }
    // RFC 4122 version 4, variant 1.
    b[6] = static_cast<std::byte>((static_cast<unsigned>(b[6]) & 0x0F) | 0x40);
    b[8] = static_cast<std::byte>((static_cast<unsigned>(b[8]) & 0x3F) | 0x80);
    return NodeID(b);
}

std::string random_service_state_nonce(std::string_view previous) {
    static constexpr std::string_view kChars = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    auto& rng = generator();
    std::string out;
    do {
        out.clear();
        for (int i = 0; i < 16; ++i) out.push_back(kChars[rng() % kChars.size()]);
    } while (out == previous);
    return out;
}

std::uint32_t random_endpoint_id() {
    auto& rng = generator();
    std::uint32_t v;
    do v = rng();
    while (v == 0);
    return v;
}

}  // namespace rr::server
