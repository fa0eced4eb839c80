// The sequence generator of the official Robot Raconteur test suite (robotraconteur/robotraconteur,
// test/lfsr: a 32-bit Fibonacci linear-feedback shift register with the feedback polynomial
// x^32 + x^22 + x^2 + x + 1, seeded from a number and a string key), written from its description.
// Every value is drawn from the register's next state(s), so a client and a service that agree on the
// seed and the key (usually the member name with `_get` / `_set`) agree on every value.
//
//   step        the next state: the feedback bit (bits 0, 1, 21 and 31 of the state XORed) enters at
//               the top, the state shifts right by one.
//   init_key    the seed stepped 128 times, stepped once more, then Jenkins' one-at-a-time hash of the
//               key's bytes on top of that (per byte: add it, add the hash shifted left 10, XOR the hash
//               shifted right 6; then add <<3, XOR >>11, add <<15), stepped 128 times, stepped once.
//   8/16/32-bit the low bytes of the next state (little-endian), as that type;
//   64-bit      two steps: the first state is the high word, the second the low word (and the state);
//   float       the next state's bits; double: the 64-bit value's bits (NaN and infinities included);
//   bool        the lowest bit of the next state; complex: the real part, then the imaginary part;
//   char        one of the 95 printable ASCII characters ' '…'~', by the next state modulo 95;
//   len(max)    next state modulo max when max < 32, else 8 + next state modulo (max − 8);
//   dist(a, b)  a + next state modulo (b − a + 1).
// Keys are ASCII (the official implementations differ for bytes above 127).
#pragma once

#include <complex>
#include <cstdint>
#include <string>
#include <string_view>

namespace rr::testsvc {

class Lfsr {
public:
    static std::uint32_t step(std::uint32_t state) noexcept;
    static std::uint32_t init_key(std::uint32_t seed, std::string_view key) noexcept;

    Lfsr(std::uint32_t seed, std::string_view key) noexcept : state_(init_key(seed, key)) {}
    /// A generator continuing from a raw state (no key).
    static Lfsr from_state(std::uint32_t state) noexcept { return Lfsr(state); }
    std::uint32_t state() const noexcept { return state_; }

    std::int8_t next_int8() noexcept { return static_cast<std::int8_t>(next()); }
    std::uint8_t next_uint8() noexcept { return static_cast<std::uint8_t>(next()); }
    std::int16_t next_int16() noexcept { return static_cast<std::int16_t>(next()); }
    std::uint16_t next_uint16() noexcept { return static_cast<std::uint16_t>(next()); }
    std::int32_t next_int32() noexcept { return static_cast<std::int32_t>(next()); }
    std::uint32_t next_uint32() noexcept { return next(); }
    std::uint64_t next_uint64() noexcept;
    std::int64_t next_int64() noexcept { return static_cast<std::int64_t>(next_uint64()); }
    float next_float() noexcept;
    double next_double() noexcept;
    bool next_bool() noexcept { return (next() & 1u) != 0; }
    std::complex<float> next_cfloat() noexcept;
    std::complex<double> next_cdouble() noexcept;
    char next_char() noexcept;
    /// Precondition: max_len > 0.
    std::uint32_t next_len(std::uint32_t max_len) noexcept;
    /// Precondition: max > min.
    std::uint32_t next_dist(std::uint32_t min, std::uint32_t max) noexcept;
    std::string next_string(std::size_t length);
    /// A string of next_len(max_len) characters.
    std::string next_string_var_len(std::uint32_t max_len);

private:
    explicit Lfsr(std::uint32_t state) noexcept : state_(state) {}
    std::uint32_t next() noexcept { return state_ = step(state_); }

    std::uint32_t state_;
};

}  // namespace rr::testsvc
