#include "test/testsvc/value_fill.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "core/value/named_type.hpp"

namespace rr::testsvc {
namespace {

constexpr std::uint32_t kMaxVarLength = 16;  // T[]: 0…15 items; strings 0…15 characters
constexpr int kMaxStructDepth = 4;

struct Shape {
    std::size_t count = 1;
    std::vector<std::uint32_t> dims;  // multi-dim only
};

Shape draw_shape(const robdef::TypeDefinition& t, Lfsr& g) {
    Shape s;
    if (t.array == robdef::ArrayKind::array) {
        const auto rule = array_length_rule(t);
        if (rule.length == 0)
            s.count = g.next_len(kMaxVarLength);
        else if (rule.exact)
            s.count = rule.length;
        else
            s.count = g.next_len(static_cast<std::uint32_t>(rule.length + 1));
    } else if (t.array == robdef::ArrayKind::multidimarray) {
        s.dims = fixed_dims(t);
        if (s.dims.empty()) {
            const std::uint32_t n = g.next_dist(1, 3);
            for (std::uint32_t i = 0; i < n; ++i) s.dims.push_back(g.next_dist(1, 4));
        }
        s.count = 1;
        for (auto d : s.dims) s.count *= d;
    }
    return s;
}

NumericArray numbers(DataTypes type, std::size_t count, Lfsr& g) {
    NumericArray a = NumericArray::zeros(type, count);
    dispatch_numeric(type, [&](auto tag) {
        using T = typename decltype(tag)::type;
        for (T& x : a.mutable_span<T>()) {
            if constexpr (std::is_same_v<T, double>) x = g.next_double();
            else if constexpr (std::is_same_v<T, float>) x = g.next_float();
            else if constexpr (std::is_same_v<T, bool>) x = g.next_bool();
            else if constexpr (std::is_same_v<T, cdouble>) x = g.next_cdouble();
            else if constexpr (std::is_same_v<T, csingle>) x = g.next_cfloat();
            else if constexpr (std::is_same_v<T, std::int8_t>) x = g.next_int8();
            else if constexpr (std::is_same_v<T, std::uint8_t>) x = g.next_uint8();
            else if constexpr (std::is_same_v<T, std::int16_t>) x = g.next_int16();
            else if constexpr (std::is_same_v<T, std::uint16_t>) x = g.next_uint16();
            else if constexpr (std::is_same_v<T, std::int32_t>) x = g.next_int32();
            else if constexpr (std::is_same_v<T, std::uint32_t>) x = g.next_uint32();
            else if constexpr (std::is_same_v<T, std::int64_t>) x = g.next_int64();
            else x = g.next_uint64();
        }
    });
    return a;
}

Value numeric_value(DataTypes type, const robdef::TypeDefinition& t, Lfsr& g) {
    Shape s = draw_shape(t, g);
    NumericArray a = numbers(type, s.count, g);
    if (t.array == robdef::ArrayKind::multidimarray) return Value(MultiDimArray{std::move(s.dims), std::move(a)});
    return Value(std::move(a));
}

Result<Value> fill(const robdef::TypeDefinition& t, Lfsr& g, const robdef::TypeLookup& lookup, std::string_view ctx,
                   int depth);

Result<Value> fill_varvalue(Lfsr& g) {
    robdef::TypeDefinition t;
    switch (g.next_dist(0, 3)) {
        case 0:
            t.base = DataTypes::double_t;
            t.array = robdef::ArrayKind::array;
            return numeric_value(DataTypes::double_t, t, g);
        case 1:
            t.base = DataTypes::int32_t;
            t.array = robdef::ArrayKind::array;
            return numeric_value(DataTypes::int32_t, t, g);
        case 2: return Value(g.next_string_var_len(kMaxVarLength));
        default:
            t.base = DataTypes::double_t;
            t.array = robdef::ArrayKind::multidimarray;
            return numeric_value(DataTypes::double_t, t, g);
    }
}

Result<Value> fill_named(const robdef::TypeDefinition& t, Lfsr& g, const robdef::TypeLookup& lookup,
                         std::string_view ctx, int depth) {
    auto nt = resolve_named_type(t, lookup, ctx);
    if (!nt) return nt.take_error();
    const std::string_view own = nt->service->name;  // unqualified names inside the type are its service's
    switch (nt->kind) {
        case robdef::NamedTypeKind::enumeration: {
            const auto& values = nt->enumeration->values;
            if (values.empty()) return fail(MessageErrorType::DataTypeError, "enum " + nt->qualified_name + " has no values");
            const std::size_t i = values.size() > 1 ? g.next_dist(0, static_cast<std::uint32_t>(values.size() - 1)) : 0;
            return Value(Enum{nt->qualified_name, values[i].value});
        }
        case robdef::NamedTypeKind::structure: {
            if (depth >= kMaxStructDepth) return Value();
            Structure s;
            s.type_name = nt->qualified_name;
            for (const auto& f : nt->entry->members) {
                auto v = fill(f.type, g, lookup, own, depth + 1);
                if (!v) return v.take_error();
                s.set(f.name, std::move(*v));
            }
            return Value(std::move(s));
        }
        case robdef::NamedTypeKind::pod: {
            Shape shape = draw_shape(t, g);
            std::vector<std::string> names;
            for (const auto& f : nt->entry->members) names.push_back(f.name);
            PodArray p(nt->qualified_name, std::move(names));
            for (std::size_t i = 0; i < shape.count; ++i) {
                std::vector<Value> item;
                for (const auto& f : nt->entry->members) {
                    auto v = fill(f.type, g, lookup, own, depth + 1);
                    if (!v) return v.take_error();
                    item.push_back(std::move(*v));
                }
                if (auto r = p.push_back(std::move(item)); !r) return r.take_error();
            }
            p.dims = std::move(shape.dims);
            return Value(std::move(p));
        }
        case robdef::NamedTypeKind::namedarray: {
            auto layout = namedarray_layout(*nt, lookup);
            if (!layout) return layout.take_error();
            Shape shape = draw_shape(t, g);
            return Value(NamedArray{nt->qualified_name, numbers(layout->element_type, shape.count * layout->elements_per_item, g),
                                    std::move(shape.dims)});
        }
        default: return fail(MessageErrorType::DataTypeError, "no value has type " + nt->qualified_name);
    }
}

Result<Value> fill(const robdef::TypeDefinition& t, Lfsr& g, const robdef::TypeLookup& lookup, std::string_view ctx,
                   int depth) {
    using robdef::ContainerKind;
    if (t.container == ContainerKind::list || t.container == ContainerKind::map_int32 ||
        t.container == ContainerKind::map_string) {
        const robdef::TypeDefinition item = without_container(t);
        const std::uint32_t n = g.next_dist(1, 3);
        if (t.container == ContainerKind::list) {
            List l;
            for (std::uint32_t i = 0; i < n; ++i) {
                auto v = fill(item, g, lookup, ctx, depth);
                if (!v) return v.take_error();
                l.items.push_back(std::move(*v));
            }
            return Value(std::move(l));
        }
        if (t.container == ContainerKind::map_int32) {
            MapInt32 m;
            std::set<std::int32_t> used;
            for (std::uint32_t i = 0; i < n; ++i) {
                std::int32_t key;
                do key = static_cast<std::int32_t>(g.next_dist(0, 999));
                while (!used.insert(key).second);
                auto v = fill(item, g, lookup, ctx, depth);
                if (!v) return v.take_error();
                m.entries.emplace_back(key, std::move(*v));
            }
            return Value(std::move(m));
        }
        MapString m;
        std::set<std::string> used;
        for (std::uint32_t i = 0; i < n; ++i) {
            std::string key;
            do key = g.next_string(g.next_dist(1, 8));
            while (!used.insert(key).second);
            auto v = fill(item, g, lookup, ctx, depth);
            if (!v) return v.take_error();
            m.entries.emplace_back(std::move(key), std::move(*v));
        }
        return Value(std::move(m));
    }
    if (t.container != ContainerKind::none)
        return fail(MessageErrorType::DataTypeError, "no value has type " + type_text(t));
    if (t.base == DataTypes::varvalue_t && t.array == robdef::ArrayKind::none) return fill_varvalue(g);
    if (t.base == DataTypes::string_t && t.array == robdef::ArrayKind::none)
        return Value(g.next_string_var_len(kMaxVarLength));
    if (is_numeric(t.base)) return numeric_value(t.base, t, g);
    if (t.base == DataTypes::namedtype_t) return fill_named(t, g, lookup, ctx, depth);
    return fail(MessageErrorType::DataTypeError, "no value has type " + type_text(t));
}

bool same_number(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

bool same_numbers(const NumericArray& a, const NumericArray& b) {
    if (a.type() != b.type() || a.size() != b.size()) return false;
    return dispatch_numeric(a.type(), [&](auto tag) {
        using T = typename decltype(tag)::type;
        auto va = a.view<T>();
        auto vb = b.view<T>();
        for (std::size_t i = 0; i < a.size(); ++i) {
            const T x = va[i], y = vb[i];
            if constexpr (std::is_same_v<T, cdouble> || std::is_same_v<T, csingle>) {
                if (!same_number(x.real(), y.real()) || !same_number(x.imag(), y.imag())) return false;
            } else if constexpr (std::is_floating_point_v<T>) {
                if (!same_number(x, y)) return false;
            } else if (x != y) {
                return false;
            }
        }
        return true;
    });
}

}  // namespace

Result<Value> lfsr_value(const robdef::TypeDefinition& type, Lfsr& gen, const robdef::TypeLookup& lookup,
                         std::string_view context_service) {
    return fill(type, gen, lookup, context_service, 0);
}

bool same_value(const Value& a, const Value& b) {
    if (a.kind() != b.kind()) return false;
    switch (a.kind()) {
        case ValueKind::null: return true;
        case ValueKind::numeric: return same_numbers(*a.get_if<NumericArray>(), *b.get_if<NumericArray>());
        case ValueKind::string: return *a.get_if<std::string>() == *b.get_if<std::string>();
        case ValueKind::multidim: {
            const auto &x = *a.get_if<MultiDimArray>(), &y = *b.get_if<MultiDimArray>();
            return x.dims == y.dims && same_numbers(x.array, y.array);
        }
        case ValueKind::structure: {
            const auto &x = *a.get_if<Structure>(), &y = *b.get_if<Structure>();
            if (x.type_name != y.type_name || x.fields.size() != y.fields.size()) return false;
            for (const auto& f : x.fields) {
                const Value* other = y.find(f.name);
                if (!other || !same_value(f.value, *other)) return false;
            }
            return true;
        }
        case ValueKind::pod: {
            const auto &x = *a.get_if<PodArray>(), &y = *b.get_if<PodArray>();
            if (x.type_name != y.type_name || x.count != y.count || x.dims != y.dims ||
                x.field_names.size() != y.field_names.size())
                return false;
            for (std::size_t i = 0; i < x.count; ++i)
                for (const auto& name : x.field_names) {
                    const Value *fx = x.field(i, name), *fy = y.field(i, name);
                    if (!fx || !fy || !same_value(*fx, *fy)) return false;
                }
            return true;
        }
        case ValueKind::namedarray: {
            const auto &x = *a.get_if<NamedArray>(), &y = *b.get_if<NamedArray>();
            return x.type_name == y.type_name && x.dims == y.dims && same_numbers(x.array, y.array);
        }
        case ValueKind::map_int32: {
            const auto &x = *a.get_if<MapInt32>(), &y = *b.get_if<MapInt32>();
            if (x.entries.size() != y.entries.size()) return false;
            for (const auto& [k, v] : x.entries) {
                const Value* other = y.find(k);
                if (!other || !same_value(v, *other)) return false;
            }
            return true;
        }
        case ValueKind::map_string: {
            const auto &x = *a.get_if<MapString>(), &y = *b.get_if<MapString>();
            if (x.entries.size() != y.entries.size()) return false;
            for (const auto& [k, v] : x.entries) {
                const Value* other = y.find(k);
                if (!other || !same_value(v, *other)) return false;
            }
            return true;
        }
        case ValueKind::list: {
            const auto &x = *a.get_if<List>(), &y = *b.get_if<List>();
            if (x.items.size() != y.items.size()) return false;
            for (std::size_t i = 0; i < x.items.size(); ++i)
                if (!same_value(x.items[i], y.items[i])) return false;
            return true;
        }
        case ValueKind::enumeration: return a.get_if<Enum>()->value == b.get_if<Enum>()->value;
    }
    return false;
}

}  // namespace rr::testsvc
