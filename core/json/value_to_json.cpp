// Value → JSON (docs/json-mapping.md).
#include <exception>
#include <optional>

#include "core/json/json_numbers.hpp"
#include "core/json/namedarray_shape.hpp"
#include "core/json/utf8.hpp"
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

json dims_json(const std::vector<std::uint32_t>& dims) { return json(dims); }

json multidim_json(const std::vector<std::uint32_t>& dims, json array) {
    json o = json::object();
    o["dims"] = dims_json(dims);
    o["array"] = std::move(array);
    return o;
}

class ToJson {
public:
    ToJson(const robdef::TypeLookup& lookup, std::size_t max_depth, BinaryArrays* binary)
        : lookup_(lookup), binary_(binary), cache_(lookup), path_({}), max_depth_(max_depth) {}

    Result<json> to(const Value& v, const TypeDefinition& t, std::string_view ctx);

private:
    struct Depth {
        explicit Depth(std::size_t& d) : d_(d) { ++d_; }
        ~Depth() { --d_; }
        std::size_t& d_;
    };

    Unexpected err(MessageErrorType type, std::string_view msg) const { return path_.error(type, msg); }
    Unexpected relay(const RRError& e) const { return path_.error(e.type, e.message); }
    Unexpected expected(const TypeDefinition& t, std::string_view qualified, const Value& v) const {
        std::string got(value_kind_name(v.kind()));
        if (auto* a = v.get_if<NumericArray>()) got = std::string(data_type_keyword(a->type())) + " " + got;
        return err(v.is_null() ? MessageErrorType::NullValue : MessageErrorType::DataTypeMismatch,
                   "expected " + type_text(t, qualified) + ", got " + got);
    }
    Result<void> check_type_name(const std::string& have, const NamedType& nt) const {
        if (!have.empty() && have != nt.qualified_name)
            return err(MessageErrorType::DataTypeMismatch, "expected type " + nt.qualified_name + ", got " + have);
        return {};
    }
    Result<std::string> checked_string(const std::string& s) const {
        if (!is_valid_utf8(s)) return err(MessageErrorType::DataTypeError, "string is not valid UTF-8");
        return s;
    }

    Result<json> container(const Value& v, const TypeDefinition& t, std::string_view ctx);
    Result<json> numeric(const Value& v, const TypeDefinition& t);
    Result<json> named(const Value& v, const TypeDefinition& t, std::string_view ctx);
    Result<json> structure(const Value& v, const TypeDefinition& t, const NamedType& nt);
    Result<json> pod(const Value& v, const TypeDefinition& t, const NamedType& nt);
    /// `scalar`: one item shown without an index in error paths.
    Result<json> pod_items(const PodArray& p, const NamedType& nt, bool scalar = false);
    Result<json> pod_field(const Value& v, const PodFieldPlan& plan);
    Result<json> namedarray(const Value& v, const TypeDefinition& t, const NamedType& nt);
    Result<json> namedarray_items(const NamedArray& a, const NamedType& nt, std::size_t& items);
    json namedarray_object(const NumericArray& a, std::size_t& offset, const NamedArrayShape& shape);
    Result<json> var(const Value& v);

    /// The numeric array as JSON numbers, or as a {"$binary": …} reference when binary_ is set.
    json array_json(const NumericArray& a);

    const robdef::TypeLookup& lookup_;
    BinaryArrays* binary_;
    TypeCache cache_;
    NamedArrayShapeCache shapes_;
    ValuePath path_;
    std::size_t depth_ = 0;
    std::size_t max_depth_;
};

Result<json> ToJson::to(const Value& v, const TypeDefinition& t, std::string_view ctx) {
    Depth d(depth_);
    if (depth_ > max_depth_) return err(MessageErrorType::ProtocolError, "value nested too deeply");
    if (t.container != ContainerKind::none) return container(v, t, ctx);
    if (is_numeric(t.base)) return numeric(v, t);
    switch (t.base) {
        case DataTypes::void_t:
            if (!v.is_null()) return err(MessageErrorType::DataTypeMismatch, "expected void (null)");
            return json(nullptr);
        case DataTypes::string_t: {
            if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "string arrays are not allowed");
            auto* s = v.get_if<std::string>();
            if (!s) return expected(t, {}, v);
            auto c = checked_string(*s);
            if (!c) return c.take_error();
            return json(std::move(*c));
        }
        case DataTypes::varvalue_t:
            if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "varvalue arrays are not supported");
            return var(v);
        case DataTypes::namedtype_t: return named(v, t, ctx);
        default: return err(MessageErrorType::DataTypeError, "\"" + t.to_string() + "\" is not a value type");
    }
}

Result<json> ToJson::container(const Value& v, const TypeDefinition& t, std::string_view ctx) {
    if (t.container == ContainerKind::generator) return err(MessageErrorType::DataTypeError, "a generator is not a value type");
    if (v.is_null()) return json(nullptr);
    TypeDefinition item_type = without_container(t);
    switch (t.container) {
        case ContainerKind::list: {
            auto* l = v.get_if<List>();
            if (!l) return expected(t, {}, v);
            json::array_t out;
            out.reserve(l->items.size());
            for (std::size_t i = 0; i < l->items.size(); ++i) {
                PathScope ps(path_, static_cast<std::int64_t>(i));
                auto j = to(l->items[i], item_type, ctx);
                if (!j) return j;
                out.push_back(std::move(*j));
            }
            return json(std::move(out));
        }
        case ContainerKind::map_int32: {
            auto* m = v.get_if<MapInt32>();
            if (!m) return expected(t, {}, v);
            json out = json::object();
            for (const auto& [key, item] : m->entries) {
                PathScope ps(path_, key);
                std::string k = std::to_string(key);
                if (out.contains(k)) return err(MessageErrorType::DataTypeError, "duplicate map key");
                auto j = to(item, item_type, ctx);
                if (!j) return j;
                out[k] = std::move(*j);
            }
            return out;
        }
        case ContainerKind::map_string: {
            auto* m = v.get_if<MapString>();
            if (!m) return expected(t, {}, v);
            json out = json::object();
            for (const auto& [key, item] : m->entries) {
                PathScope ps(path_, PathScope::Key{key});
                if (!is_valid_utf8(key)) return err(MessageErrorType::DataTypeError, "map key is not valid UTF-8");
                if (out.contains(key)) return err(MessageErrorType::DataTypeError, "duplicate map key");
                auto j = to(item, item_type, ctx);
                if (!j) return j;
                out[key] = std::move(*j);
            }
            return out;
        }
        default: return err(MessageErrorType::DataTypeError, "unknown container");
    }
}

Result<json> ToJson::numeric(const Value& v, const TypeDefinition& t) {
    if (t.array == ArrayKind::multidimarray) {
        auto* m = v.get_if<MultiDimArray>();
        if (!m || m->array.type() != t.base) return expected(t, {}, m ? Value(m->array) : v);
        if (auto r = check_dims(m->dims, m->array.size(), t); !r) return relay(r.error());
        return multidim_json(m->dims, array_json(m->array));
    }
    auto* a = v.get_if<NumericArray>();
    if (!a || a->type() != t.base) return expected(t, {}, v);
    if (auto r = check_count(a->size(), t); !r) return relay(r.error());
    if (t.array == ArrayKind::none) return json_numbers::item_to_json(*a, 0);
    return array_json(*a);
}

json ToJson::array_json(const NumericArray& a) {
    if (!binary_ || a.type() == DataTypes::bool_t) return json_numbers::array_to_json(a);
    json ref = json::object();
    ref["$binary"] = binary_->blobs.size();
    ref["type"] = std::string(data_type_keyword(a.type()));
    ref["length"] = a.size();
    ref["offset"] = binary_->bytes;
    binary_->blobs.push_back(a.to_bytes());
    binary_->bytes += BinaryArrays::padded(binary_->blobs.back().size());
    return ref;
}

Result<json> ToJson::named(const Value& v, const TypeDefinition& t, std::string_view ctx) {
    auto nt = resolve_named_type(t, lookup_, ctx);
    if (!nt) return relay(nt.error());
    switch (nt->kind) {
        case NamedTypeKind::structure: return structure(v, t, *nt);
        case NamedTypeKind::pod: return pod(v, t, *nt);
        case NamedTypeKind::namedarray: return namedarray(v, t, *nt);
        case NamedTypeKind::enumeration: {
            if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "enum arrays are not allowed");
            if (auto* e = v.get_if<Enum>()) {
                if (auto r = check_type_name(e->type_name, *nt); !r) return r.take_error();
                return json(e->value);
            }
            if (auto* a = v.get_if<NumericArray>(); a && a->type() == DataTypes::int32_t && a->size() == 1)
                return json(a->at<std::int32_t>(0));
            return expected(t, nt->qualified_name, v);
        }
        default: return err(MessageErrorType::DataTypeError, "\"" + nt->qualified_name + "\" is not a value type");
    }
}

Result<json> ToJson::structure(const Value& v, const TypeDefinition& t, const NamedType& nt) {
    if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "struct arrays are not allowed");
    if (v.is_null()) return json(nullptr);
    auto* s = v.get_if<Structure>();
    if (!s) return expected(t, nt.qualified_name, v);
    if (auto r = check_type_name(s->type_name, nt); !r) return r.take_error();
    json out = json::object();
    std::size_t matched = 0;
    for (const auto& m : nt.entry->members) {
        if (m.kind != robdef::MemberKind::field) continue;
        PathScope ps(path_, m.name);
        const Value* fv = s->find(m.name);
        if (!fv) return err(MessageErrorType::DataTypeError, "missing field of " + nt.qualified_name);
        ++matched;
        auto j = to(*fv, m.type, nt.service->name);
        if (!j) return j;
        out[m.name] = std::move(*j);
    }
    if (matched != s->fields.size()) return err(MessageErrorType::DataTypeError, "unknown or duplicate field in " + nt.qualified_name);
    return out;
}

Result<json> ToJson::pod(const Value& v, const TypeDefinition& t, const NamedType& nt) {
    auto* p = v.get_if<PodArray>();
    if (!p) return expected(t, nt.qualified_name, v);
    if (auto r = check_type_name(p->type_name, nt); !r) return r.take_error();
    if (t.array == ArrayKind::multidimarray) {
        if (auto r = check_dims(p->dims, p->count, t); !r) return relay(r.error());
        auto items = pod_items(*p, nt);
        if (!items) return items;
        return multidim_json(p->dims, std::move(*items));
    }
    if (!p->dims.empty()) return err(MessageErrorType::DataTypeError, "multi-dim pod array where " + type_text(t, nt.qualified_name) + " expected");
    if (auto r = check_count(p->count, t); !r) return relay(r.error());
    auto items = pod_items(*p, nt, t.array == ArrayKind::none);
    if (!items) return items;
    if (t.array == ArrayKind::none) return std::move((*items)[0]);
    return items;
}

// Array of item objects.
Result<json> ToJson::pod_items(const PodArray& p, const NamedType& nt, bool scalar) {
    auto cached = cache_.pod_plans(nt);
    if (!cached) return relay(cached.error());
    const std::vector<PodFieldPlan>& plans = **cached;
    const std::size_t nf = p.field_names.size();
    if (p.values.size() != p.count * nf)
        return err(MessageErrorType::DataTypeError, "pod value holds a wrong number of field values");
    std::vector<std::size_t> index(plans.size());
    for (std::size_t k = 0; k < plans.size(); ++k) {
        auto at = p.field_index(plans[k].member->name);
        if (at < 0) {
            PathScope ps(path_, plans[k].member->name);
            return err(MessageErrorType::DataTypeError, "missing field of " + nt.qualified_name);
        }
        index[k] = static_cast<std::size_t>(at);
    }
    if (plans.size() != nf) return err(MessageErrorType::DataTypeError, "unknown or duplicate field in " + nt.qualified_name);
    json::array_t out;
    out.reserve(p.count);
    for (std::size_t i = 0; i < p.count; ++i) {
        std::optional<PathScope> pi;
        if (!scalar) pi.emplace(path_, static_cast<std::int64_t>(i));
        json item = json::object();
        for (std::size_t k = 0; k < plans.size(); ++k) {
            const PodFieldPlan& plan = plans[k];
            PathScope pf(path_, plan.member->name);
            auto j = pod_field(p.values[i * nf + index[k]], plan);
            if (!j) return j;
            item[plan.member->name] = std::move(*j);
        }
        out.push_back(std::move(item));
    }
    return json(std::move(out));
}

Result<json> ToJson::pod_field(const Value& v, const PodFieldPlan& plan) {
    Depth d(depth_);
    if (depth_ > max_depth_) return err(MessageErrorType::ProtocolError, "value nested too deeply");
    const TypeDefinition& wt = plan.wire_type;
    if (!plan.multidim) {
        if (wt.base != DataTypes::namedtype_t) return numeric(v, wt);
        if (plan.named.kind == NamedTypeKind::pod) return pod(v, wt, plan.named);
        return namedarray(v, wt, plan.named);
    }
    // Multi-dim field: shown as {"dims": declared dims, "array": flat items}.
    const TypeDefinition& decl = plan.member->type;
    auto check = [&](const std::vector<std::uint32_t>& dims, std::size_t n) -> Result<void> {
        if (auto r = check_dims(dims.empty() ? plan.dims : dims, n, decl); !r) return relay(r.error());
        return {};
    };
    if (is_numeric(wt.base)) {
        const NumericArray* a = nullptr;
        std::vector<std::uint32_t> dims;
        if (auto* m = v.get_if<MultiDimArray>()) {
            a = &m->array;
            dims = m->dims;
        } else {
            a = v.get_if<NumericArray>();
        }
        if (!a || a->type() != wt.base) return expected(decl, {}, a ? Value(*a) : v);
        if (auto r = check(dims, a->size()); !r) return r.take_error();
        return multidim_json(plan.dims, array_json(*a));
    }
    if (plan.named.kind == NamedTypeKind::pod) {
        auto* p = v.get_if<PodArray>();
        if (!p) return expected(decl, plan.named.qualified_name, v);
        if (auto r = check_type_name(p->type_name, plan.named); !r) return r.take_error();
        if (auto r = check(p->dims, p->count); !r) return r.take_error();
        auto items = pod_items(*p, plan.named);
        if (!items) return items;
        return multidim_json(plan.dims, std::move(*items));
    }
    auto* a = v.get_if<NamedArray>();
    if (!a) return expected(decl, plan.named.qualified_name, v);
    if (auto r = check_type_name(a->type_name, plan.named); !r) return r.take_error();
    std::size_t items = 0;
    auto j = namedarray_items(*a, plan.named, items);
    if (!j) return j;
    if (auto r = check(a->dims, items); !r) return r.take_error();
    return multidim_json(plan.dims, std::move(*j));
}

Result<json> ToJson::namedarray(const Value& v, const TypeDefinition& t, const NamedType& nt) {
    auto* a = v.get_if<NamedArray>();
    if (!a) return expected(t, nt.qualified_name, v);
    if (auto r = check_type_name(a->type_name, nt); !r) return r.take_error();
    std::size_t items = 0;
    auto j = namedarray_items(*a, nt, items);
    if (!j) return j;
    if (t.array == ArrayKind::multidimarray) {
        if (auto r = check_dims(a->dims, items, t); !r) return relay(r.error());
        return multidim_json(a->dims, std::move(*j));
    }
    if (!a->dims.empty())
        return err(MessageErrorType::DataTypeError, "multi-dim namedarray where " + type_text(t, nt.qualified_name) + " expected");
    if (auto r = check_count(items, t); !r) return relay(r.error());
    if (t.array == ArrayKind::none) return std::move((*j)[0]);
    return j;
}

Result<json> ToJson::namedarray_items(const NamedArray& a, const NamedType& nt, std::size_t& items) {
    auto shape = shapes_.get(nt, lookup_);
    if (!shape) return relay(shape.error());
    const NamedArrayShape& s = **shape;
    if (a.array.type() != s.element_type)
        return err(MessageErrorType::DataTypeMismatch, "namedarray " + nt.qualified_name + " stores " +
                                                           std::string(data_type_keyword(s.element_type)) + ", got " +
                                                           std::string(data_type_keyword(a.array.type())));
    if (a.array.size() % s.width != 0)
        return err(MessageErrorType::DataTypeError, "namedarray data length " + std::to_string(a.array.size()) +
                                                        " is not a multiple of " + std::to_string(s.width));
    items = a.array.size() / s.width;
    json::array_t out;
    out.reserve(items);
    std::size_t offset = 0;
    for (std::size_t i = 0; i < items; ++i) out.push_back(namedarray_object(a.array, offset, s));
    return json(std::move(out));
}

json ToJson::namedarray_object(const NumericArray& a, std::size_t& offset, const NamedArrayShape& shape) {
    json o = json::object();
    for (const auto& m : shape.members) {
        auto one = [&]() -> json {
            if (m.nested) return namedarray_object(a, offset, *m.nested);
            return json_numbers::item_to_json(a, offset++);
        };
        if (!m.array) {
            o[std::string(m.name)] = one();
        } else {
            json::array_t arr;
            arr.reserve(m.count);
            for (std::size_t k = 0; k < m.count; ++k) arr.push_back(one());
            o[std::string(m.name)] = json(std::move(arr));
        }
    }
    return o;
}

Result<json> ToJson::var(const Value& v) {
    if (v.is_null()) return json(nullptr);
    std::string type = var_type_string(v);
    TypeDefinition t;
    if (v.kind() == ValueKind::enumeration && v.get_if<Enum>()->type_name.empty()) {
        t.base = DataTypes::int32_t;
        auto j = to(Value::scalar(v.get_if<Enum>()->value), t, {});
        if (!j) return j;
        return json{{"type", "int32"}, {"value", std::move(*j)}};
    }
    auto parsed = parse_type_string(type);
    if (!parsed) return err(MessageErrorType::DataTypeError, "varvalue holds a named value without a type name");
    t = std::move(*parsed);
    if (t.base == DataTypes::namedtype_t) t.qualified_name = t.type_name;
    auto j = to(v, t, {});
    if (!j) return j;
    json o = json::object();
    o["type"] = std::move(type);
    o["value"] = std::move(*j);
    return o;
}

}  // namespace

Result<json> value_to_json(const Value& value, const TypeDefinition& type, const robdef::TypeLookup& lookup,
                           std::string_view context_service, const Limits& limits, BinaryArrays* binary) {
    const std::size_t blobs_before = binary ? binary->blobs.size() : 0, bytes_before = binary ? binary->bytes : 0;
    try {
        ToJson t(lookup, limits.max_nesting_depth, binary);
        auto j = t.to(value, type, context_service);
        if (!j && binary) {  // no references to them were returned
            binary->blobs.resize(blobs_before);
            binary->bytes = bytes_before;
        }
        return j;
    } catch (const std::exception& e) {
        if (binary) {
            binary->blobs.resize(blobs_before);
            binary->bytes = bytes_before;
        }
        return fail(MessageErrorType::InternalError, std::string("JSON: ") + e.what());
    }
}

}  // namespace rr
