// The value recipes of com.robotraconteur.testing.TestService3 (pods, namedarrays, teststruct3) as the
// official clients expect them. The official test draws these values from a counter walking over two
// tables, one of doubles and one of uint32 (robotraconteur/robotraconteur, test/python ServiceTest2.py
// and test/cpp/service ServiceTest2.cpp, "ServiceTest2_test_sequence_gen"):
//   counter = seed mod 7823, step = seed mod 17 + 7;
//   next double = doubles[(counter += step) mod size], next uint32 likewise from uint32s,
//   next int8 = (counter += step) mod 255 − 128.
// The tables are data of the official repository: SequenceTables::official() takes them from an
// official values file (official_values.hpp), made from a checkout of that repository by
// test/testsvc/official_values.py and never kept in this one. SequenceTables::lfsr() makes tables of
// the same sizes from the LFSR (doubles are uint32 / 2^32, in [0, 1)); test/testsvc/testsvc_values.py
// builds the same, so CI checks run without the official data.
//
// The recipes (each seeds its own counter; `u` is the next uint32 of that counter):
//   transform         7 doubles (rotation q0…q3, translation x, y, z)
//   transform array   n transforms, the i-th from seed u
//   testpod2          i1 = int8; i2 = 15 int8; i3 = (u mod 15) int8
//   testpod1          d1; d2 = 6 doubles; d3 = (u mod 6) doubles; d4 = 9 doubles (3×3, column-major);
//                     s1 = testpod2(u); s2 = 8 × testpod2(u); s3 = (u mod 9) × testpod2(u);
//                     s4 = 8 × testpod2(u) (2×4); t1 = transform(u); t2 = 4 × transform(u);
//                     t3 = (u mod 15) × transform(u); t4 = 8 × transform(u) (2×4)
//   testpod1 array    n testpod1s, the i-th from seed u; multi-dim m×n: m·n of them, column-major
//   teststruct3       see fill_teststruct3 (each field from the next u, lengths from some of them)
#pragma once

#include <cstdint>
#include <vector>

#include "core/value/value.hpp"

namespace rr::testsvc {

struct SequenceTables {
    std::vector<double> doubles;
    std::vector<std::uint32_t> uint32s;

    /// Tables of the official sizes (7919 doubles, 7727 uint32) drawn from Lfsr(seed, "sequence_doubles")
    /// and Lfsr(seed, "sequence_uint32s").
    static SequenceTables lfsr(std::uint32_t seed);
};

class SequenceGen {
public:
    /// Precondition: both tables non-empty.
    SequenceGen(const SequenceTables& tables, std::uint32_t seed)
        : tables_(&tables), counter_(seed % 7823), step_(seed % 17 + 7) {}
    double next_double() { return tables_->doubles[(counter_ += step_) % tables_->doubles.size()]; }
    std::uint32_t next_uint32() { return tables_->uint32s[(counter_ += step_) % tables_->uint32s.size()]; }
    std::int8_t next_int8() { return static_cast<std::int8_t>(static_cast<int>((counter_ += step_) % 255) - 128); }

private:
    const SequenceTables* tables_;
    std::uint64_t counter_;
    std::uint64_t step_;
};

/// Builds the TestService3 values of the recipes above, with qualified type names.
class Ts3Values {
public:
    explicit Ts3Values(const SequenceTables& tables) : tables_(tables) {}

    Value transform(std::uint32_t seed) const;
    /// The `translation` of transform(seed) (a vector3).
    Value vector3_of_transform(std::uint32_t seed) const;
    Value transform_array(std::size_t n, std::uint32_t seed) const;
    Value transform_multidim(std::uint32_t m, std::uint32_t n, std::uint32_t seed) const;
    Value testpod2(std::uint32_t seed) const;
    Value testpod1(std::uint32_t seed) const;
    Value testpod1_array(std::size_t n, std::uint32_t seed) const;
    Value testpod1_multidim(std::uint32_t m, std::uint32_t n, std::uint32_t seed) const;
    Value teststruct3(std::uint32_t seed) const;

private:
    std::vector<double> transform_numbers(std::uint32_t seed) const;
    std::vector<Value> testpod2_fields(std::uint32_t seed) const;
    std::vector<Value> testpod1_fields(std::uint32_t seed) const;
    Value testpod2_items(SequenceGen& g, std::size_t n, std::vector<std::uint32_t> dims) const;
    Value transform_items(SequenceGen& g, std::size_t n, std::vector<std::uint32_t> dims) const;

    const SequenceTables& tables_;
};

}  // namespace rr::testsvc
