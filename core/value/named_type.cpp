#include "core/value/named_type.hpp"

namespace rr {

using robdef::ArrayKind;
using robdef::ContainerKind;
using robdef::EntryKind;
using robdef::MemberKind;
using robdef::NamedTypeKind;
using robdef::TypeDefinition;

Result<NamedType> resolve_named_type(std::string_view name, const robdef::TypeLookup& lookup,
                                     std::string_view context_service) {
    robdef::NamedTypeRef ref = lookup.find(name, context_service);
    if (!ref || (!ref.entry && !ref.enumeration))
        return fail(MessageErrorType::DataTypeError, "unknown named type \"" + std::string(name) + "\"");
    NamedType t;
    t.service = ref.service;
    t.entry = ref.entry;
    t.enumeration = ref.enumeration;
    const std::string& short_name = ref.entry ? ref.entry->name : ref.enumeration->name;
    t.qualified_name = ref.service->name + "." + short_name;
    if (ref.enumeration) {
        t.kind = NamedTypeKind::enumeration;
    } else {
        switch (ref.entry->kind) {
            case EntryKind::structure: t.kind = NamedTypeKind::structure; break;
            case EntryKind::pod: t.kind = NamedTypeKind::pod; break;
            case EntryKind::namedarray: t.kind = NamedTypeKind::namedarray; break;
            case EntryKind::object: t.kind = NamedTypeKind::object; break;
        }
    }
    return t;
}

Result<NamedType> resolve_named_type(const TypeDefinition& type, const robdef::TypeLookup& lookup,
                                     std::string_view context_service) {
    if (!type.qualified_name.empty()) return resolve_named_type(type.qualified_name, lookup, {});
    return resolve_named_type(type.type_name, lookup, context_service);
}

namespace {

constexpr int kMaxNamedArrayDepth = 16;

Result<void> add_namedarray_members(const NamedType& type, const robdef::TypeLookup& lookup, int depth,
                                    NamedArrayLayout& out) {
    if (depth > kMaxNamedArrayDepth)
        return fail(MessageErrorType::DataTypeError,
                    "namedarray \"" + type.qualified_name + "\" nests too deeply (recursive definition?)");
    for (const auto& m : type.entry->members) {
        if (m.kind != MemberKind::field) continue;
        const TypeDefinition& ft = m.type;
        auto bad = [&](std::string_view why) {
            return fail(MessageErrorType::DataTypeError, "invalid namedarray \"" + type.qualified_name +
                                                             "\" field \"" + m.name + "\": " + std::string(why));
        };
        if (ft.container != ContainerKind::none) return bad("containers are not allowed");
        std::size_t n = 1;
        if (ft.array != ArrayKind::none) {
            if (ft.array_var_length || ft.array_length.empty()) return bad("arrays must have a fixed length");
            std::vector<std::uint32_t> dims;
            for (auto d : ft.array_length) {
                if (d <= 0) return bad("arrays must have a fixed length");
                dims.push_back(static_cast<std::uint32_t>(d));
            }
            if (!dims_product(dims, n, 1u << 24)) return bad("array too large");
        }
        if (is_numeric(ft.base)) {
            if (out.element_type != DataTypes::void_t && out.element_type != ft.base)
                return bad("all elements must have the same numeric type");
            out.element_type = ft.base;
            out.elements_per_item += n;
        } else if (ft.base == DataTypes::namedtype_t) {
            auto nested = resolve_named_type(ft, lookup, type.service->name);
            if (!nested) return nested.take_error();
            if (nested->kind != NamedTypeKind::namedarray) return bad("only numeric and namedarray fields allowed");
            NamedArrayLayout inner;
            if (auto r = add_namedarray_members(*nested, lookup, depth + 1, inner); !r) return r;
            if (inner.elements_per_item == 0) return bad("empty namedarray");
            if (out.element_type != DataTypes::void_t && out.element_type != inner.element_type)
                return bad("all elements must have the same numeric type");
            out.element_type = inner.element_type;
            out.elements_per_item += n * inner.elements_per_item;
        } else {
            return bad("only numeric and namedarray fields allowed");
        }
        if (out.elements_per_item > (1u << 24)) return bad("namedarray too large");
    }
    return {};
}

}  // namespace

Result<NamedArrayLayout> namedarray_layout(const NamedType& type, const robdef::TypeLookup& lookup) {
    NamedArrayLayout out;
    if (type.kind != NamedTypeKind::namedarray || !type.entry)
        return fail(MessageErrorType::DataTypeError, "\"" + type.qualified_name + "\" is not a namedarray");
    if (auto r = add_namedarray_members(type, lookup, 0, out); !r) return r.take_error();
    if (out.elements_per_item == 0)
        return fail(MessageErrorType::DataTypeError, "namedarray \"" + type.qualified_name + "\" has no elements");
    return out;
}

ArrayLengthRule array_length_rule(const TypeDefinition& type) noexcept {
    ArrayLengthRule r;
    if (type.array != ArrayKind::array || type.array_length.empty() || type.array_length[0] <= 0) return r;
    r.length = static_cast<std::size_t>(type.array_length[0]);
    r.exact = !type.array_var_length;
    return r;
}

std::vector<std::uint32_t> fixed_dims(const TypeDefinition& type) {
    std::vector<std::uint32_t> dims;
    if (type.array != ArrayKind::multidimarray || type.array_var_length) return dims;
    for (auto d : type.array_length) dims.push_back(d > 0 ? static_cast<std::uint32_t>(d) : 0u);
    return dims;
}

bool dims_product(const std::vector<std::uint32_t>& dims, std::size_t& product, std::size_t max) noexcept {
    std::size_t p = 1;
    for (auto d : dims) {
        if (d != 0 && p > max / d) return false;
        p *= d;
    }
    if (p > max) return false;
    product = p;
    return true;
}

TypeDefinition without_container(const TypeDefinition& type) {
    TypeDefinition t = type;
    t.container = ContainerKind::none;
    return t;
}

TypeDefinition pod_field_wire_type(const TypeDefinition& type) {
    if (type.array != ArrayKind::multidimarray) return type;
    TypeDefinition t = type;
    std::size_t n = 0;
    auto dims = fixed_dims(type);
    if (dims.empty() || !dims_product(dims, n, 0x7fffffff)) n = 0;
    t.array = ArrayKind::array;
    t.array_var_length = false;
    t.array_length = {static_cast<std::int32_t>(n)};
    return t;
}

std::string type_text(const TypeDefinition& type, std::string_view qualified_name) {
    if (qualified_name.empty() || type.base != DataTypes::namedtype_t) return type.to_string();
    TypeDefinition t = type;
    t.type_name = std::string(qualified_name);
    return t.to_string();
}

}  // namespace rr
