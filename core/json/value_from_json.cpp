// JSON → Value (docs/json-mapping.md).
#include <algorithm>
#include <charconv>
#include <exception>
#include <optional>

#include "core/json/json_numbers.hpp"
#include "core/json/namedarray_shape.hpp"
#include "core/json/value_json.hpp"
#include "core/value/element_layout.hpp"
#include "core/value/named_type.hpp"
#include "core/value/type_cache.hpp"
#include "core/value/value_path.hpp"
#include "core/value/var_type.hpp"

namespace rr {

using nlohmann::json;
using robdef::ArrayKind;
using robdef::ContainerKind;
using robdef::NamedTypeKind;
using robdef::TypeDefinition;

namespace {

/// The int32 whose canonical decimal text is `key` ("-5", "0", "17"; not "+5", "05", "-0").
std::optional<std::int32_t> canonical_int32(const std::string& key) {
    std::int32_t v = 0;
    auto [p, ec] = std::from_chars(key.data(), key.data() + key.size(), v);
    if (ec != std::errc() || p != key.data() + key.size() || std::to_string(v) != key) return std::nullopt;
    return v;
}

class FromJson {
public:
    FromJson(const robdef::TypeLookup& lookup, std::size_t max_depth)
        : lookup_(lookup), cache_(lookup), path_({}), max_depth_(max_depth) {}

    Result<Value> from(const json& j, const TypeDefinition& t, std::string_view ctx);

private:
    struct Depth {
        explicit Depth(std::size_t& d) : d_(d) { ++d_; }
        ~Depth() { --d_; }
        std::size_t& d_;
    };

    Unexpected err(MessageErrorType type, std::string_view msg) const { return path_.error(type, msg); }
    Unexpected relay(const RRError& e) const { return path_.error(e.type, e.message); }
    Unexpected expected(const TypeDefinition& t, std::string_view qualified, const json& j, std::string_view form) const {
        return err(j.is_null() ? MessageErrorType::NullValue : MessageErrorType::DataTypeMismatch,
                   "expected " + std::string(form) + " for " + type_text(t, qualified) + ", got " +
                       std::string(j.type_name()));
    }
    /// `j` must be an object with exactly the keys "dims" and "array".
    Result<std::vector<std::uint32_t>> multidim_dims(const json& j, const TypeDefinition& t, std::string_view q);

    Result<Value> container(const json& j, const TypeDefinition& t, std::string_view ctx);
    Result<Value> numeric(const json& j, const TypeDefinition& t);
    Result<NumericArray> numbers(const json& j, DataTypes type);
    Result<Value> named(const json& j, const TypeDefinition& t, std::string_view ctx);
    Result<Value> structure(const json& j, const TypeDefinition& t, const NamedType& nt);
    Result<Value> enumeration(const json& j, const TypeDefinition& t, const NamedType& nt);
    Result<Value> pod(const json& j, const TypeDefinition& t, const NamedType& nt);
    /// `scalar`: one item shown without an index in error paths (a scalar pod / namedarray).
    Result<PodArray> pod_items(std::span<const json> items, const NamedType& nt, bool scalar = false);
    Result<std::span<const json>> array_items(const json& j, const NamedType& nt);
    Result<Value> pod_field(const json& j, const PodFieldPlan& plan);
    Result<Value> namedarray(const json& j, const TypeDefinition& t, const NamedType& nt);
    Result<NamedArray> namedarray_items(std::span<const json> items, const NamedType& nt, bool scalar = false);
    template <class T>
    Result<void> fill_namedarray(const json& obj, std::span<T> out, std::size_t& offset, const NamedArrayShape& shape);
    Result<Value> var(const json& j);

    const robdef::TypeLookup& lookup_;
    TypeCache cache_;
    NamedArrayShapeCache shapes_;
    ValuePath path_;
    std::size_t depth_ = 0;
    std::size_t max_depth_;
};

Result<Value> FromJson::from(const json& j, const TypeDefinition& t, std::string_view ctx) {
    Depth d(depth_);
    if (depth_ > max_depth_) return err(MessageErrorType::ProtocolError, "value nested too deeply");
    if (t.container != ContainerKind::none) return container(j, t, ctx);
    if (is_numeric(t.base)) return numeric(j, t);
    switch (t.base) {
        case DataTypes::void_t:
            if (!j.is_null()) return err(MessageErrorType::DataTypeMismatch, "expected null for void");
            return Value();
        case DataTypes::string_t:
            if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "string arrays are not allowed");
            if (!j.is_string()) return expected(t, {}, j, "a string");
            return Value(j.get<std::string>());
        case DataTypes::varvalue_t:
            if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "varvalue arrays are not supported");
            return var(j);
        case DataTypes::namedtype_t: return named(j, t, ctx);
        default: return err(MessageErrorType::DataTypeError, "\"" + t.to_string() + "\" is not a value type");
    }
}

Result<std::vector<std::uint32_t>> FromJson::multidim_dims(const json& j, const TypeDefinition& t, std::string_view q) {
    if (!j.is_object()) return expected(t, q, j, "{\"dims\":[…],\"array\":[…]}");
    if (j.size() != 2 || !j.contains("dims") || !j.contains("array"))
        return err(MessageErrorType::DataTypeError, "a multi-dim array is {\"dims\":[…],\"array\":[…]}");
    PathScope ps(path_, "dims");
    std::size_t bad = 0;
    auto dims = json_numbers::array_from_json(j["dims"], DataTypes::uint32_t, &bad);
    if (!dims) {
        if (!j["dims"].is_array()) return relay(dims.error());
        PathScope pi(path_, static_cast<std::int64_t>(bad));
        return relay(dims.error());
    }
    auto v = dims->view<std::uint32_t>();
    return std::vector<std::uint32_t>(v.begin(), v.end());
}

Result<Value> FromJson::container(const json& j, const TypeDefinition& t, std::string_view ctx) {
    if (t.container == ContainerKind::generator) return err(MessageErrorType::DataTypeError, "a generator is not a value type");
    if (j.is_null()) return Value();
    TypeDefinition item_type = without_container(t);
    switch (t.container) {
        case ContainerKind::list: {
            if (!j.is_array()) return expected(t, {}, j, "an array");
            List l;
            l.items.reserve(j.size());
            for (std::size_t i = 0; i < j.size(); ++i) {
                PathScope ps(path_, static_cast<std::int64_t>(i));
                auto v = from(j[i], item_type, ctx);
                if (!v) return v;
                l.items.push_back(std::move(*v));
            }
            return Value(std::move(l));
        }
        case ContainerKind::map_int32: {
            if (!j.is_object()) return expected(t, {}, j, "an object");
            MapInt32 m;
            m.entries.reserve(j.size());
            for (const auto& [key, item] : j.items()) {
                auto k = canonical_int32(key);
                PathScope ps(path_, PathScope::Key{key});
                if (!k) return err(MessageErrorType::DataTypeError, "int32 map keys are decimal int32 text");
                auto v = from(item, item_type, ctx);
                if (!v) return v;
                m.entries.emplace_back(*k, std::move(*v));
            }
            // Object members come in text order; give the map its numeric key order (as CORE sends maps).
            std::sort(m.entries.begin(), m.entries.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
            return Value(std::move(m));
        }
        case ContainerKind::map_string: {
            if (!j.is_object()) return expected(t, {}, j, "an object");
            MapString m;
            m.entries.reserve(j.size());
            for (const auto& [key, item] : j.items()) {
                PathScope ps(path_, PathScope::Key{key});
                auto v = from(item, item_type, ctx);
                if (!v) return v;
                m.entries.emplace_back(key, std::move(*v));
            }
            return Value(std::move(m));
        }
        default: return err(MessageErrorType::DataTypeError, "unknown container");
    }
}

Result<NumericArray> FromJson::numbers(const json& j, DataTypes type) {
    std::size_t bad = 0;
    auto a = json_numbers::array_from_json(j, type, &bad);
    if (!a) {
        if (!j.is_array()) return relay(a.error());
        PathScope ps(path_, static_cast<std::int64_t>(bad));
        return relay(a.error());
    }
    return a;
}

Result<Value> FromJson::numeric(const json& j, const TypeDefinition& t) {
    if (j.is_null()) return err(MessageErrorType::NullValue, "expected " + t.to_string() + ", got null");
    if (t.array == ArrayKind::multidimarray) {
        auto dims = multidim_dims(j, t, {});
        if (!dims) return dims.take_error();
        PathScope ps(path_, "array");
        auto a = numbers(j["array"], t.base);
        if (!a) return a.take_error();
        if (auto r = check_dims(*dims, a->size(), t); !r) return relay(r.error());
        return Value(MultiDimArray{std::move(*dims), std::move(*a)});
    }
    if (t.array == ArrayKind::none) {
        return dispatch_numeric(t.base, [&](auto tag) -> Result<Value> {
            using T = typename decltype(tag)::type;
            auto v = json_numbers::from_json<T>(j);
            if (!v) return relay(v.error());
            return Value::scalar<T>(*v);
        });
    }
    auto a = numbers(j, t.base);
    if (!a) return a.take_error();
    if (auto r = check_count(a->size(), t); !r) return relay(r.error());
    return Value(std::move(*a));
}

Result<Value> FromJson::named(const json& j, const TypeDefinition& t, std::string_view ctx) {
    auto nt = resolve_named_type(t, lookup_, ctx);
    if (!nt) return relay(nt.error());
    switch (nt->kind) {
        case NamedTypeKind::structure: return structure(j, t, *nt);
        case NamedTypeKind::pod: return pod(j, t, *nt);
        case NamedTypeKind::namedarray: return namedarray(j, t, *nt);
        case NamedTypeKind::enumeration: return enumeration(j, t, *nt);
        default: return err(MessageErrorType::DataTypeError, "\"" + nt->qualified_name + "\" is not a value type");
    }
}

Result<Value> FromJson::structure(const json& j, const TypeDefinition& t, const NamedType& nt) {
    if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "struct arrays are not allowed");
    if (j.is_null()) return Value();
    if (!j.is_object()) return expected(t, nt.qualified_name, j, "an object");
    Structure s{nt.qualified_name, {}};
    s.fields.reserve(nt.entry->members.size());
    for (const auto& m : nt.entry->members) {
        if (m.kind != robdef::MemberKind::field) continue;
        PathScope ps(path_, m.name);
        auto it = j.find(m.name);
        if (it == j.end()) return err(MessageErrorType::DataTypeError, "missing field of " + nt.qualified_name);
        auto v = from(*it, m.type, nt.service->name);
        if (!v) return v;
        s.fields.push_back(Field{m.name, std::move(*v)});
    }
    if (s.fields.size() != j.size()) {
        for (const auto& [key, item] : j.items()) {
            if (!s.find(key)) {
                PathScope ps(path_, key);
                return err(MessageErrorType::DataTypeError, "unknown field of " + nt.qualified_name);
            }
        }
    }
    return Value(std::move(s));
}

Result<Value> FromJson::enumeration(const json& j, const TypeDefinition& t, const NamedType& nt) {
    if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "enum arrays are not allowed");
    if (j.is_string()) {
        const auto& name = j.get_ref<const std::string&>();
        for (const auto& ev : nt.enumeration->values)
            if (ev.name == name) return Value(Enum{nt.qualified_name, ev.value});
        return err(MessageErrorType::InvalidArgument, "\"" + name + "\" is not a value of " + nt.qualified_name);
    }
    if (j.is_null()) return err(MessageErrorType::NullValue, "expected " + nt.qualified_name + ", got null");
    auto v = json_numbers::from_json<std::int32_t>(j);
    if (!v) return relay(v.error());
    return Value(Enum{nt.qualified_name, *v});
}

Result<Value> FromJson::pod(const json& j, const TypeDefinition& t, const NamedType& nt) {
    if (j.is_null()) return err(MessageErrorType::NullValue, "expected " + type_text(t, nt.qualified_name) + ", got null");
    if (t.array == ArrayKind::multidimarray) {
        auto dims = multidim_dims(j, t, nt.qualified_name);
        if (!dims) return dims.take_error();
        PathScope ps(path_, "array");
        auto arr = array_items(j["array"], nt);
        if (!arr) return arr.take_error();
        auto p = pod_items(*arr, nt);
        if (!p) return p.take_error();
        if (auto r = check_dims(*dims, p->count, t); !r) return relay(r.error());
        p->dims = std::move(*dims);
        return Value(std::move(*p));
    }
    if (t.array == ArrayKind::none) {
        if (!j.is_object()) return expected(t, nt.qualified_name, j, "an object");
        auto p = pod_items(std::span<const json>(&j, 1), nt, true);
        if (!p) return p.take_error();
        return Value(std::move(*p));
    }
    auto arr = array_items(j, nt);
    if (!arr) return arr.take_error();
    auto p = pod_items(*arr, nt);
    if (!p) return p.take_error();
    if (auto r = check_count(p->count, t); !r) return relay(r.error());
    return Value(std::move(*p));
}

Result<std::span<const json>> FromJson::array_items(const json& j, const NamedType& nt) {
    if (!j.is_array())
        return err(MessageErrorType::DataTypeMismatch, "expected an array of " + nt.qualified_name + " objects, got " +
                                                           std::string(j.type_name()));
    const auto& a = j.get_ref<const json::array_t&>();
    return std::span<const json>(a.data(), a.size());
}

Result<PodArray> FromJson::pod_items(std::span<const json> items, const NamedType& nt, bool scalar) {
    auto cached = cache_.pod_plans(nt);
    if (!cached) return relay(cached.error());
    const std::vector<PodFieldPlan>& plans = **cached;
    PodArray p;
    p.type_name = nt.qualified_name;
    for (const auto& plan : plans) p.field_names.push_back(plan.member->name);
    p.values.reserve(items.size() * plans.size());
    for (std::size_t i = 0; i < items.size(); ++i) {
        std::optional<PathScope> pi;
        if (!scalar) pi.emplace(path_, static_cast<std::int64_t>(i));
        const json& item = items[i];
        if (!item.is_object())
            return err(MessageErrorType::DataTypeMismatch, "expected a " + nt.qualified_name + " object, got " +
                                                               std::string(item.type_name()));
        if (item.size() != plans.size()) {
            for (const auto& [key, v] : item.items()) {
                if (p.field_index(key) < 0) {
                    PathScope pf(path_, key);
                    return err(MessageErrorType::DataTypeError, "unknown field of " + nt.qualified_name);
                }
            }
        }
        for (const auto& plan : plans) {
            PathScope pf(path_, plan.member->name);
            auto it = item.find(plan.member->name);
            if (it == item.end()) return err(MessageErrorType::DataTypeError, "missing field of " + nt.qualified_name);
            auto v = pod_field(*it, plan);
            if (!v) return v.take_error();
            p.values.push_back(std::move(*v));
        }
        ++p.count;
    }
    return p;
}

Result<Value> FromJson::pod_field(const json& j, const PodFieldPlan& plan) {
    Depth d(depth_);
    if (depth_ > max_depth_) return err(MessageErrorType::ProtocolError, "value nested too deeply");
    const TypeDefinition& wt = plan.wire_type;
    if (!plan.multidim) {
        if (wt.base != DataTypes::namedtype_t) return numeric(j, wt);
        if (plan.named.kind == NamedTypeKind::pod) return pod(j, wt, plan.named);
        return namedarray(j, wt, plan.named);
    }
    // Multi-dim field: {"dims": the declared dims, "array": flat items}.
    const TypeDefinition& decl = plan.member->type;
    if (j.is_null()) return err(MessageErrorType::NullValue, "expected " + decl.to_string() + ", got null");
    auto dims = multidim_dims(j, decl, plan.named.qualified_name);
    if (!dims) return dims.take_error();
    PathScope ps(path_, "array");
    const json& arr = j["array"];
    std::size_t count = 0;
    Value out;
    if (is_numeric(wt.base)) {
        auto a = numbers(arr, wt.base);
        if (!a) return a.take_error();
        count = a->size();
        out = Value(MultiDimArray{*dims, std::move(*a)});
    } else {
        auto items = array_items(arr, plan.named);
        if (!items) return items.take_error();
        count = items->size();
        if (plan.named.kind == NamedTypeKind::pod) {
            auto p = pod_items(*items, plan.named);
            if (!p) return p.take_error();
            p->dims = *dims;
            out = Value(std::move(*p));
        } else {
            auto a = namedarray_items(*items, plan.named);
            if (!a) return a.take_error();
            a->dims = *dims;
            out = Value(std::move(*a));
        }
    }
    if (auto r = check_dims(*dims, count, decl); !r) return relay(r.error());
    return out;
}

Result<Value> FromJson::namedarray(const json& j, const TypeDefinition& t, const NamedType& nt) {
    if (j.is_null()) return err(MessageErrorType::NullValue, "expected " + type_text(t, nt.qualified_name) + ", got null");
    if (t.array == ArrayKind::multidimarray) {
        auto dims = multidim_dims(j, t, nt.qualified_name);
        if (!dims) return dims.take_error();
        PathScope ps(path_, "array");
        auto arr = array_items(j["array"], nt);
        if (!arr) return arr.take_error();
        auto a = namedarray_items(*arr, nt);
        if (!a) return a.take_error();
        if (auto r = check_dims(*dims, arr->size(), t); !r) return relay(r.error());
        a->dims = std::move(*dims);
        return Value(std::move(*a));
    }
    if (t.array == ArrayKind::none) {
        if (!j.is_object()) return expected(t, nt.qualified_name, j, "an object");
        auto a = namedarray_items(std::span<const json>(&j, 1), nt, true);
        if (!a) return a.take_error();
        return Value(std::move(*a));
    }
    auto arr = array_items(j, nt);
    if (!arr) return arr.take_error();
    auto a = namedarray_items(*arr, nt);
    if (!a) return a.take_error();
    if (auto r = check_count(arr->size(), t); !r) return relay(r.error());
    return Value(std::move(*a));
}

template <class T>
Result<void> FromJson::fill_namedarray(const json& obj, std::span<T> out, std::size_t& offset,
                                       const NamedArrayShape& shape) {
    if (!obj.is_object())
        return err(MessageErrorType::DataTypeMismatch, "expected a namedarray object, got " + std::string(obj.type_name()));
    if (obj.size() != shape.members.size()) {
        for (const auto& item : obj.items()) {
            const std::string& key = item.key();
            if (std::none_of(shape.members.begin(), shape.members.end(), [&](auto& m) { return m.name == key; })) {
                PathScope ps(path_, key);
                return err(MessageErrorType::DataTypeError, "unknown namedarray field");
            }
        }
    }
    for (const auto& m : shape.members) {
        PathScope ps(path_, m.name);
        auto it = obj.find(std::string(m.name));
        if (it == obj.end()) return err(MessageErrorType::DataTypeError, "missing namedarray field");
        auto one = [&](const json& j) -> Result<void> {
            if (m.nested) return fill_namedarray<T>(j, out, offset, *m.nested);
            auto v = json_numbers::from_json<T>(j);
            if (!v) return relay(v.error());
            out[offset++] = *v;
            return {};
        };
        if (!m.array) {
            if (auto r = one(*it); !r) return r;
            continue;
        }
        if (!it->is_array()) return err(MessageErrorType::DataTypeMismatch, "expected an array of " + std::to_string(m.count));
        if (it->size() != m.count)
            return err(MessageErrorType::DataTypeError,
                       "expected " + std::to_string(m.count) + " items, got " + std::to_string(it->size()));
        for (std::size_t k = 0; k < m.count; ++k) {
            PathScope pk(path_, static_cast<std::int64_t>(k));
            if (auto r = one((*it)[k]); !r) return r;
        }
    }
    return {};
}

Result<NamedArray> FromJson::namedarray_items(std::span<const json> items, const NamedType& nt, bool scalar) {
    auto shape = shapes_.get(nt, lookup_);
    if (!shape) return relay(shape.error());
    const NamedArrayShape& s = **shape;
    NumericArray flat = NumericArray::zeros(s.element_type, items.size() * s.width);
    Result<void> ok = dispatch_numeric(s.element_type, [&](auto tag) -> Result<void> {
        using T = typename decltype(tag)::type;
        auto out = flat.mutable_span<T>();
        std::size_t offset = 0;
        for (std::size_t i = 0; i < items.size(); ++i) {
            std::optional<PathScope> pi;
            if (!scalar) pi.emplace(path_, static_cast<std::int64_t>(i));
            if (auto r = fill_namedarray<T>(items[i], out, offset, s); !r) return r;
        }
        return {};
    });
    if (!ok) return ok.take_error();
    return NamedArray{nt.qualified_name, std::move(flat), {}};
}

Result<Value> FromJson::var(const json& j) {
    if (j.is_null()) return Value();
    if (!j.is_object() || j.size() != 2 || !j.contains("type") || !j.contains("value") || !j["type"].is_string())
        return err(MessageErrorType::DataTypeError, "a varvalue is null or {\"type\":\"<RR type>\",\"value\":…}");
    auto t = parse_type_string(j["type"].get<std::string>());
    if (!t) return relay(t.error());
    if (t->base == DataTypes::void_t || (t->base == DataTypes::varvalue_t && t->container == ContainerKind::none))
        return err(MessageErrorType::DataTypeError, "a varvalue type must be a concrete type");
    if (t->base == DataTypes::namedtype_t) t->qualified_name = t->type_name;  // varvalue types are fully qualified
    PathScope ps(path_, "value");
    return from(j["value"], *t, {});
}

}  // namespace

Result<Value> value_from_json(const json& j, const TypeDefinition& type, const robdef::TypeLookup& lookup,
                              std::string_view context_service, const Limits& limits) {
    try {
        FromJson f(lookup, limits.max_nesting_depth);
        return f.from(j, type, context_service);
    } catch (const std::exception& e) {
        return fail(MessageErrorType::InternalError, std::string("JSON: ") + e.what());
    }
}

}  // namespace rr
