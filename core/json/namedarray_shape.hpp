// The field tree of a namedarray item, for showing its flat numeric array as JSON objects
// (docs/json-mapping.md §Namedarrays): item i of a namedarray array occupies elements
// [i*width, (i+1)*width) of the flat array, fields in definition order.
#pragma once

#include <memory>
#include <utility>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "core/value/named_type.hpp"

namespace rr {

struct NamedArrayShape {
    struct Member {
        std::string_view name;  ///< points into the definition
        std::size_t count = 1;  ///< items (1 for a scalar field, N for `[N]`)
        bool array = false;     ///< written with `[N]`: JSON array even when N == 1
        std::shared_ptr<const NamedArrayShape> nested;  ///< nested namedarray, or null for numeric
    };
    DataTypes element_type = DataTypes::void_t;
    std::size_t width = 0;  ///< elements per item
    std::vector<Member> members;
};

/// Shape of namedarray `type`. Errors as namedarray_layout (DataTypeError for invalid definitions).
Result<std::shared_ptr<const NamedArrayShape>> namedarray_shape(const NamedType& type,
                                                                 const robdef::TypeLookup& lookup);

/// Shapes computed once per JSON call, keyed by definition address.
class NamedArrayShapeCache {
public:
    Result<std::shared_ptr<const NamedArrayShape>> get(const NamedType& type, const robdef::TypeLookup& lookup) {
        for (const auto& [entry, shape] : shapes_)
            if (entry == type.entry) return shape;
        auto s = namedarray_shape(type, lookup);
        if (s) shapes_.emplace_back(type.entry, *s);
        return s;
    }

private:
    std::vector<std::pair<const robdef::ServiceEntryDefinition*, std::shared_ptr<const NamedArrayShape>>> shapes_;
};

}  // namespace rr
