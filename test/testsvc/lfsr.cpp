#include "test/testsvc/lfsr.hpp"

#include <bit>

namespace rr::testsvc {

std::uint32_t Lfsr::step(std::uint32_t s) noexcept {
    const std::uint32_t feedback = (s ^ (s >> 1) ^ (s >> 21) ^ (s >> 31)) & 1u;
    return (s >> 1) | (feedback << 31);
}

std::uint32_t Lfsr::init_key(std::uint32_t seed, std::string_view key) noexcept {
    for (int i = 0; i < 128; ++i) seed = step(seed);
    std::uint32_t hash = step(seed);
    for (unsigned char c : key) {
        hash += c;
        hash += hash << 10;
        hash ^= hash >> 6;
    }
    hash += hash << 3;
    hash ^= hash >> 11;
    hash += hash << 15;
    for (int i = 0; i < 128; ++i) hash = step(hash);
    return step(hash);
}

std::uint64_t Lfsr::next_uint64() noexcept {
    const std::uint64_t high = next();
    const std::uint64_t low = next();
    return (high << 32) | low;
}

float Lfsr::next_float() noexcept { return std::bit_cast<float>(next()); }

double Lfsr::next_double() noexcept { return std::bit_cast<double>(next_uint64()); }

std::complex<float> Lfsr::next_cfloat() noexcept {
    const float re = next_float();
    return {re, next_float()};
}

std::complex<double> Lfsr::next_cdouble() noexcept {
    const double re = next_double();
    return {re, next_double()};
}

char Lfsr::next_char() noexcept {
    constexpr std::uint32_t kPrintable = '~' - ' ' + 1;  // 95
    return static_cast<char>(' ' + next() % kPrintable);
}

std::uint32_t Lfsr::next_len(std::uint32_t max_len) noexcept {
    const std::uint32_t s = next();
    return max_len < 32 ? s % max_len : 8 + s % (max_len - 8);
}

std::uint32_t Lfsr::next_dist(std::uint32_t min, std::uint32_t max) noexcept {
    return next() % (max - min + 1) + min;
}

std::string Lfsr::next_string(std::size_t length) {
    std::string s(length, ' ');
    for (auto& c : s) c = next_char();
    return s;
}

std::string Lfsr::next_string_var_len(std::uint32_t max_len) { return next_string(next_len(max_len)); }

}  // namespace rr::testsvc
