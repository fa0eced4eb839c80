#include "core/json/namedarray_shape.hpp"

namespace rr {

namespace {

Result<std::shared_ptr<const NamedArrayShape>> build(const NamedType& type, const robdef::TypeLookup& lookup,
                                                     int depth) {
    if (depth > 16) return fail(MessageErrorType::DataTypeError, "namedarray nests too deeply");
    auto layout = namedarray_layout(type, lookup);  // validates the whole definition
    if (!layout) return layout.take_error();
    auto shape = std::make_shared<NamedArrayShape>();
    shape->element_type = layout->element_type;
    shape->width = layout->elements_per_item;
    for (const auto& m : type.entry->members) {
        if (m.kind != robdef::MemberKind::field) continue;
        NamedArrayShape::Member sm;
        sm.name = m.name;
        if (m.type.array != robdef::ArrayKind::none) {
            sm.array = true;
            sm.count = 1;
            for (auto d : m.type.array_length) sm.count *= static_cast<std::size_t>(d);
        }
        if (m.type.base == DataTypes::namedtype_t) {
            auto nt = resolve_named_type(m.type, lookup, type.service->name);
            if (!nt) return nt.take_error();
            auto nested = build(*nt, lookup, depth + 1);
            if (!nested) return nested.take_error();
            sm.nested = std::move(*nested);
        }
        shape->members.push_back(sm);
    }
    return std::shared_ptr<const NamedArrayShape>(std::move(shape));
}

}  // namespace

Result<std::shared_ptr<const NamedArrayShape>> namedarray_shape(const NamedType& type,
                                                                 const robdef::TypeLookup& lookup) {
    return build(type, lookup, 0);
}

}  // namespace rr
