// Test-only: deterministic corruption of element trees, to check that unpacking reports errors and
// never crashes (run under ASan/UBSan). A fixed-seed LCG keeps failures reproducible.
#pragma once

#include <cstdint>
#include <vector>

#include "base/message/message.hpp"

namespace rr::testing {

class Lcg {
public:
    explicit Lcg(std::uint64_t seed) : s_(seed) {}
    std::uint32_t next() {
        s_ = s_ * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<std::uint32_t>(s_ >> 33);
    }
    std::size_t below(std::size_t n) { return n ? next() % n : 0; }

private:
    std::uint64_t s_;
};

inline void collect(MessageElement& e, std::vector<MessageElement*>& out) {
    out.push_back(&e);
    for (auto& c : e.elements) collect(c, out);
}

/// Applies one random corruption somewhere in `root`.
inline void mutate(MessageElement& root, Lcg& rng) {
    static constexpr DataTypes kTypes[] = {
        DataTypes::void_t,       DataTypes::double_t,     DataTypes::single_t,   DataTypes::int8_t,
        DataTypes::uint8_t,      DataTypes::int32_t,      DataTypes::uint32_t,   DataTypes::int64_t,
        DataTypes::string_t,     DataTypes::cdouble_t,    DataTypes::bool_t,     DataTypes::structure_t,
        DataTypes::vector_t,     DataTypes::dictionary_t, DataTypes::list_t,     DataTypes::pod_t,
        DataTypes::pod_array_t,  DataTypes::pod_multidimarray_t, DataTypes::namedarray_array_t,
        DataTypes::namedarray_multidimarray_t, DataTypes::multidimarray_t};
    std::vector<MessageElement*> nodes;
    collect(root, nodes);
    MessageElement& e = *nodes[rng.below(nodes.size())];
    switch (rng.below(8)) {
        case 0: e.type = kTypes[rng.below(std::size(kTypes))]; break;
        case 1: e.type_name = rng.below(2) ? std::string() : std::string("example.test.Vec3"); break;
        case 2:
            if (!e.elements.empty()) e.elements.erase(e.elements.begin() + static_cast<std::ptrdiff_t>(rng.below(e.elements.size())));
            break;
        case 3:
            if (!e.elements.empty()) e.elements.push_back(e.elements[rng.below(e.elements.size())]);
            break;
        case 4:
            if (rng.below(2))
                e.number = static_cast<std::int32_t>(rng.below(5)) - 1;
            else
                e.number.reset();
            break;
        case 5:
            if (!e.data.empty()) e.data = e.data.subspan(0, rng.below(e.data.size()));
            break;
        case 6: e.name = rng.below(2) ? std::string("dims") : std::string("0"); break;
        default:
            if (e.elements.size() > 1) std::swap(e.elements[0], e.elements[e.elements.size() - 1]);
            break;
    }
}

}  // namespace rr::testing
