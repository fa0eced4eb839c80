// Per-call memo of what packing, unpacking and JSON need per named type (pod field plans, namedarray
// layouts), so an array of 10 000 pods resolves its field types once, not once per item.
// Lives for one pack/unpack/JSON call; entries are keyed by definition address. Not thread-safe.
#pragma once

#include <memory>
#include <vector>

#include "base/error/rr_error.hpp"
#include "core/value/element_layout.hpp"
#include "core/value/named_type.hpp"

namespace rr {

class TypeCache {
public:
    explicit TypeCache(const robdef::TypeLookup& lookup) : lookup_(lookup) {}

    const robdef::TypeLookup& lookup() const noexcept { return lookup_; }

    /// pod_field_plans(pod, lookup), computed once. The pointer stays valid for the cache's lifetime.
    Result<const std::vector<PodFieldPlan>*> pod_plans(const NamedType& pod);
    /// namedarray_layout(type, lookup), computed once.
    Result<NamedArrayLayout> layout(const NamedType& type);

private:
    struct PodEntry {
        const robdef::ServiceEntryDefinition* entry;
        std::vector<PodFieldPlan> plans;
    };
    struct LayoutEntry {
        const robdef::ServiceEntryDefinition* entry;
        NamedArrayLayout layout;
    };
    const robdef::TypeLookup& lookup_;
    std::vector<std::unique_ptr<PodEntry>> pods_;
    std::vector<LayoutEntry> layouts_;
};

}  // namespace rr
