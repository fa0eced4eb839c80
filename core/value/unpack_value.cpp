// MessageElement → Value (see pack_value.hpp for the layouts and errors).
#include <cstring>
#include <optional>

#include "core/value/element_layout.hpp"
#include "core/value/named_type.hpp"
#include "core/value/type_cache.hpp"
#include "core/value/pack_value.hpp"
#include "core/value/value_path.hpp"

namespace rr {

using robdef::ArrayKind;
using robdef::ContainerKind;
using robdef::NamedTypeKind;
using robdef::TypeDefinition;

namespace {

std::string element_type_text(const MessageElement& e) {
    std::string s = "element type " + std::to_string(static_cast<int>(e.type));
    auto kw = data_type_keyword(e.type);
    if (!kw.empty() && is_numeric(e.type)) s += " (" + std::string(kw) + ")";
    if (!e.type_name.empty()) s += " \"" + e.type_name + "\"";
    return s;
}

/// Walks an element tree. `lookup_` is null for untyped (varvalue-without-robdef) unpacking.
class Unpacker {
public:
    Unpacker(const robdef::TypeLookup* lookup, std::string_view root, std::size_t max_depth)
        : lookup_(lookup), path_(root), max_depth_(max_depth) {
        if (lookup_) cache_.emplace(*lookup_);
    }

    Result<Value> unpack(const MessageElement& e, const TypeDefinition& t, std::string_view ctx);
    Result<Value> unpack_var(const MessageElement& e);

private:
    struct Depth {
        explicit Depth(std::size_t& d) : d_(d) { ++d_; }
        ~Depth() { --d_; }
        std::size_t& d_;
    };

    Unexpected err(MessageErrorType type, std::string_view msg) const { return path_.error(type, msg); }
    Unexpected relay(const RRError& e) const { return path_.error(e.type, e.message); }
    Unexpected expected(const TypeDefinition& t, std::string_view qualified, const MessageElement& e) const {
        return err(e.type == DataTypes::void_t ? MessageErrorType::NullValue : MessageErrorType::DataTypeMismatch,
                   "expected " + type_text(t, qualified) + ", got " +
                       (e.type == DataTypes::void_t ? std::string("null") : element_type_text(e)));
    }
    Result<void> check_type_name(const MessageElement& e, const NamedType& nt) const {
        if (e.type_name != nt.qualified_name)
            return err(MessageErrorType::DataTypeMismatch,
                       "expected type " + nt.qualified_name + ", got \"" + e.type_name + "\"");
        return {};
    }
    Result<const MessageElement*> child(const MessageElement& e, std::string_view name) {
        const MessageElement* c = e.find(name);
        if (!c) {
            PathScope ps(path_, name);
            return err(MessageErrorType::MessageElementNotFound, "missing element");
        }
        return c;
    }

    Result<Value> unpack_container(const MessageElement& e, const TypeDefinition& t, std::string_view ctx);
    Result<NumericArray> unpack_array(const MessageElement& e, DataTypes type);
    Result<Value> unpack_numeric(const MessageElement& e, const TypeDefinition& t);
    Result<Value> unpack_multidim(const MessageElement& e, const TypeDefinition* t);
    Result<std::vector<std::uint32_t>> unpack_dims(const MessageElement& parent);
    Result<Value> unpack_named(const MessageElement& e, const TypeDefinition& t, std::string_view ctx);
    Result<Value> unpack_struct(const MessageElement& e, const TypeDefinition& t, const NamedType& nt);
    Result<Value> unpack_pod(const MessageElement& e, const TypeDefinition& t, const NamedType& nt);
    Result<PodArray> unpack_pod_items(const MessageElement& e, const TypeDefinition& t, const NamedType& nt);
    Result<Value> unpack_pod_field(const MessageElement& e, const PodFieldPlan& plan);
    Result<Value> unpack_namedarray(const MessageElement& e, const TypeDefinition& t, const NamedType& nt);
    Result<NamedArray> unpack_namedarray_items(const MessageElement& e, const TypeDefinition& t,
                                               const NamedType& nt, std::size_t* items_out = nullptr);
    Result<Value> unpack_var_typed(const MessageElement& e);
    Result<Value> unpack_struct_untyped(const MessageElement& e);
    Result<PodArray> unpack_pod_untyped(const MessageElement& e);
    Result<NamedArray> unpack_namedarray_untyped(const MessageElement& e);

    const robdef::TypeLookup* lookup_;
    std::optional<TypeCache> cache_;  ///< set when lookup_ is
    ValuePath path_;
    std::size_t depth_ = 0;
    std::size_t max_depth_;
};

Result<Value> Unpacker::unpack(const MessageElement& e, const TypeDefinition& t, std::string_view ctx) {
    Depth d(depth_);
    if (depth_ > max_depth_) return err(MessageErrorType::ProtocolError, "value nested too deeply");
    if (t.container != ContainerKind::none) return unpack_container(e, t, ctx);
    if (is_numeric(t.base)) return unpack_numeric(e, t);
    switch (t.base) {
        case DataTypes::void_t: return Value();
        case DataTypes::string_t: {
            if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "string arrays are not allowed");
            if (e.type != DataTypes::string_t) return expected(t, {}, e);
            std::string s(e.data.size(), '\0');
            if (!s.empty()) std::memcpy(s.data(), e.data.data(), s.size());
            return Value(std::move(s));
        }
        case DataTypes::varvalue_t:
            if (t.array != ArrayKind::none)
                return err(MessageErrorType::DataTypeError, "varvalue arrays are not supported");
            return unpack_var(e);
        case DataTypes::namedtype_t: return unpack_named(e, t, ctx);
        default: return err(MessageErrorType::DataTypeError, "\"" + t.to_string() + "\" is not a value type");
    }
}

Result<Value> Unpacker::unpack_container(const MessageElement& e, const TypeDefinition& t, std::string_view ctx) {
    if (t.container == ContainerKind::generator)
        return err(MessageErrorType::DataTypeError, "a generator is not a value type");
    if (e.type == DataTypes::void_t) return Value();
    TypeDefinition item_type = without_container(t);
    switch (t.container) {
        case ContainerKind::list: {
            if (e.type != DataTypes::list_t) return expected(t, {}, e);
            List l;
            l.items.reserve(e.elements.size());
            for (std::size_t i = 0; i < e.elements.size(); ++i) {
                PathScope ps(path_, static_cast<std::int64_t>(i));
                auto n = element_number(e.elements[i]);
                if (!n || static_cast<std::size_t>(*n) != i)
                    return err(MessageErrorType::DataTypeError, "list items must be numbered 0..n-1 in order");
                auto v = unpack(e.elements[i], item_type, ctx);
                if (!v) return v.take_error();
                l.items.push_back(std::move(*v));
            }
            return Value(std::move(l));
        }
        case ContainerKind::map_int32: {
            if (e.type != DataTypes::vector_t) return expected(t, {}, e);
            MapInt32 m;
            m.entries.reserve(e.elements.size());
            for (const auto& c : e.elements) {
                auto n = element_number(c);
                if (!n) {
                    PathScope ps(path_, c.name);
                    return err(MessageErrorType::DataTypeError, "int32 map item without a number");
                }
                PathScope ps(path_, *n);
                if (m.find(*n)) return err(MessageErrorType::DataTypeError, "duplicate map key");
                auto v = unpack(c, item_type, ctx);
                if (!v) return v.take_error();
                m.entries.emplace_back(*n, std::move(*v));
            }
            return Value(std::move(m));
        }
        case ContainerKind::map_string: {
            if (e.type != DataTypes::dictionary_t) return expected(t, {}, e);
            MapString m;
            m.entries.reserve(e.elements.size());
            for (const auto& c : e.elements) {
                if (c.number) {
                    PathScope ps(path_, *c.number);
                    return err(MessageErrorType::DataTypeError, "string map item without a name");
                }
                PathScope ps(path_, PathScope::Key{c.name});
                if (m.find(c.name)) return err(MessageErrorType::DataTypeError, "duplicate map key");
                auto v = unpack(c, item_type, ctx);
                if (!v) return v.take_error();
                m.entries.emplace_back(c.name, std::move(*v));
            }
            return Value(std::move(m));
        }
        default: return err(MessageErrorType::DataTypeError, "unknown container");
    }
}

Result<NumericArray> Unpacker::unpack_array(const MessageElement& e, DataTypes type) {
    if (e.type != type) {
        if (e.type == DataTypes::void_t) return err(MessageErrorType::NullValue, "numeric array must not be null");
        return err(MessageErrorType::DataTypeMismatch, "expected " + std::string(data_type_keyword(type)) +
                                                           " array, got " + element_type_text(e));
    }
    auto a = NumericArray::wrap(e.type, e.data);
    if (!a) return relay(a.error());
    return a;
}

Result<Value> Unpacker::unpack_numeric(const MessageElement& e, const TypeDefinition& t) {
    if (t.array == ArrayKind::multidimarray) {
        if (e.type != DataTypes::multidimarray_t) return expected(t, {}, e);
        return unpack_multidim(e, &t);
    }
    if (e.type != t.base) return expected(t, {}, e);
    auto a = unpack_array(e, t.base);
    if (!a) return a.take_error();
    if (auto r = check_count(a->size(), t); !r) return relay(r.error());
    return Value(std::move(*a));
}

Result<std::vector<std::uint32_t>> Unpacker::unpack_dims(const MessageElement& parent) {
    auto d = child(parent, "dims");
    if (!d) return d.take_error();
    PathScope ps(path_, "dims");
    auto a = unpack_array(**d, DataTypes::uint32_t);
    if (!a) return a.take_error();
    if (a->empty()) return err(MessageErrorType::DataTypeError, "multi-dim array needs at least one dim");
    auto v = a->view<std::uint32_t>();
    return std::vector<std::uint32_t>(v.begin(), v.end());
}

// `t` null: varvalue (any numeric type, any shape).
Result<Value> Unpacker::unpack_multidim(const MessageElement& e, const TypeDefinition* t) {
    auto dims = unpack_dims(e);
    if (!dims) return dims.take_error();
    auto arr = child(e, "array");
    if (!arr) return arr.take_error();
    PathScope ps(path_, "array");
    DataTypes want = t ? t->base : (*arr)->type;
    if (!is_numeric(want)) return err(MessageErrorType::DataTypeError, "multi-dim array must be numeric");
    auto a = unpack_array(**arr, want);
    if (!a) return a.take_error();
    TypeDefinition any;
    any.array = ArrayKind::multidimarray;
    any.array_var_length = true;
    if (auto r = check_dims(*dims, a->size(), t ? *t : any); !r) return relay(r.error());
    return Value(MultiDimArray{std::move(*dims), std::move(*a)});
}

Result<Value> Unpacker::unpack_named(const MessageElement& e, const TypeDefinition& t, std::string_view ctx) {
    auto nt = resolve_named_type(t, *lookup_, ctx);
    if (!nt) return relay(nt.error());
    switch (nt->kind) {
        case NamedTypeKind::structure: return unpack_struct(e, t, *nt);
        case NamedTypeKind::pod: return unpack_pod(e, t, *nt);
        case NamedTypeKind::namedarray: return unpack_namedarray(e, t, *nt);
        case NamedTypeKind::enumeration: {
            if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "enum arrays are not allowed");
            if (e.type != DataTypes::int32_t) return expected(t, nt->qualified_name, e);
            auto a = unpack_array(e, DataTypes::int32_t);
            if (!a) return a.take_error();
            if (auto r = check_count(a->size(), t); !r) return relay(r.error());
            return Value(Enum{nt->qualified_name, a->at<std::int32_t>(0)});
        }
        default: return err(MessageErrorType::DataTypeError, "\"" + nt->qualified_name + "\" is not a value type");
    }
}

Result<Value> Unpacker::unpack_struct(const MessageElement& e, const TypeDefinition& t, const NamedType& nt) {
    if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "struct arrays are not allowed");
    if (e.type == DataTypes::void_t) return Value();
    if (e.type != DataTypes::structure_t) return expected(t, nt.qualified_name, e);
    if (auto r = check_type_name(e, nt); !r) return r.take_error();
    Structure s{nt.qualified_name, {}};
    s.fields.reserve(nt.entry->members.size());
    for (const auto& m : nt.entry->members) {
        if (m.kind != robdef::MemberKind::field) continue;
        auto c = child(e, m.name);
        if (!c) return c.take_error();
        PathScope ps(path_, m.name);
        auto v = unpack(**c, m.type, nt.service->name);
        if (!v) return v.take_error();
        s.fields.push_back(Field{m.name, std::move(*v)});
    }
    return Value(std::move(s));
}

Result<Value> Unpacker::unpack_pod(const MessageElement& e, const TypeDefinition& t, const NamedType& nt) {
    if (t.array == ArrayKind::multidimarray) {
        if (e.type != DataTypes::pod_multidimarray_t) return expected(t, nt.qualified_name, e);
        if (auto r = check_type_name(e, nt); !r) return r.take_error();
        auto dims = unpack_dims(e);
        if (!dims) return dims.take_error();
        auto arr = child(e, "array");
        if (!arr) return arr.take_error();
        PathScope ps(path_, "array");
        TypeDefinition flat = t;
        flat.array = ArrayKind::array;
        flat.array_var_length = true;
        flat.array_length.clear();
        auto p = unpack_pod_items(**arr, flat, nt);
        if (!p) return p.take_error();
        if (auto r = check_dims(*dims, p->count, t); !r) return relay(r.error());
        p->dims = std::move(*dims);
        return Value(std::move(*p));
    }
    auto p = unpack_pod_items(e, t, nt);
    if (!p) return p.take_error();
    return Value(std::move(*p));
}

Result<PodArray> Unpacker::unpack_pod_items(const MessageElement& e, const TypeDefinition& t, const NamedType& nt) {
    if (e.type != DataTypes::pod_array_t) return expected(t, nt.qualified_name, e);
    if (auto r = check_type_name(e, nt); !r) return r.take_error();
    if (auto r = check_count(e.elements.size(), t); !r) return relay(r.error());
    auto cached = cache_->pod_plans(nt);
    if (!cached) return relay(cached.error());
    const std::vector<PodFieldPlan>& plans = **cached;
    PodArray p;
    p.type_name = nt.qualified_name;
    p.field_names.reserve(plans.size());
    for (const auto& plan : plans) p.field_names.push_back(plan.member->name);
    p.values.reserve(e.elements.size() * plans.size());
    for (std::size_t i = 0; i < e.elements.size(); ++i) {
        PathScope pi(path_, static_cast<std::int64_t>(i));
        const MessageElement& item = e.elements[i];
        auto n = element_number(item);
        if (!n || static_cast<std::size_t>(*n) != i)
            return err(MessageErrorType::DataTypeError, "pod array items must be numbered 0..n-1 in order");
        if (item.type != DataTypes::pod_t)
            return err(MessageErrorType::DataTypeMismatch, "expected a pod item (109), got " + element_type_text(item));
        for (const auto& plan : plans) {
            auto c = child(item, plan.member->name);
            if (!c) return c.take_error();
            PathScope pf(path_, plan.member->name);
            auto v = unpack_pod_field(**c, plan);
            if (!v) return v.take_error();
            p.values.push_back(std::move(*v));
        }
        ++p.count;
    }
    return p;
}

Result<Value> Unpacker::unpack_pod_field(const MessageElement& e, const PodFieldPlan& plan) {
    Depth d(depth_);
    if (depth_ > max_depth_) return err(MessageErrorType::ProtocolError, "value nested too deeply");
    const TypeDefinition& wt = plan.wire_type;
    if (is_numeric(wt.base)) {
        auto v = unpack_numeric(e, wt);
        if (!v || !plan.multidim) return v;
        return Value(MultiDimArray{plan.dims, std::move(*v->get_if<NumericArray>())});
    }
    if (plan.named.kind == NamedTypeKind::pod) {
        auto p = unpack_pod_items(e, wt, plan.named);
        if (!p) return p.take_error();
        if (plan.multidim) p->dims = plan.dims;
        return Value(std::move(*p));
    }
    auto a = unpack_namedarray_items(e, wt, plan.named);
    if (!a) return a.take_error();
    if (plan.multidim) a->dims = plan.dims;
    return Value(std::move(*a));
}

Result<Value> Unpacker::unpack_namedarray(const MessageElement& e, const TypeDefinition& t, const NamedType& nt) {
    if (t.array == ArrayKind::multidimarray) {
        if (e.type != DataTypes::namedarray_multidimarray_t) return expected(t, nt.qualified_name, e);
        if (auto r = check_type_name(e, nt); !r) return r.take_error();
        auto dims = unpack_dims(e);
        if (!dims) return dims.take_error();
        auto arr = child(e, "array");
        if (!arr) return arr.take_error();
        PathScope ps(path_, "array");
        TypeDefinition flat = t;
        flat.array = ArrayKind::array;
        flat.array_var_length = true;
        flat.array_length.clear();
        std::size_t items = 0;
        auto a = unpack_namedarray_items(**arr, flat, nt, &items);
        if (!a) return a.take_error();
        if (auto r = check_dims(*dims, items, t); !r) return relay(r.error());
        a->dims = std::move(*dims);
        return Value(std::move(*a));
    }
    auto a = unpack_namedarray_items(e, t, nt);
    if (!a) return a.take_error();
    return Value(std::move(*a));
}

Result<NamedArray> Unpacker::unpack_namedarray_items(const MessageElement& e, const TypeDefinition& t,
                                                     const NamedType& nt, std::size_t* items_out) {
    if (e.type != DataTypes::namedarray_array_t) return expected(t, nt.qualified_name, e);
    if (auto r = check_type_name(e, nt); !r) return r.take_error();
    auto layout = cache_->layout(nt);
    if (!layout) return relay(layout.error());
    auto arr = child(e, "array");
    if (!arr) return arr.take_error();
    PathScope ps(path_, "array");
    auto a = unpack_array(**arr, layout->element_type);
    if (!a) return a.take_error();
    if (a->size() % layout->elements_per_item != 0)
        return err(MessageErrorType::DataTypeError,
                   "namedarray data length " + std::to_string(a->size()) + " is not a multiple of " +
                       std::to_string(layout->elements_per_item));
    std::size_t items = a->size() / layout->elements_per_item;
    if (auto r = check_count(items, t); !r) return relay(r.error());
    if (items_out) *items_out = items;
    return NamedArray{nt.qualified_name, std::move(*a), {}};
}

Result<Value> Unpacker::unpack_var(const MessageElement& e) {
    Depth d(depth_);
    if (depth_ > max_depth_) return err(MessageErrorType::ProtocolError, "value nested too deeply");
    if (e.type == DataTypes::void_t) return Value();
    if (is_numeric(e.type)) {
        auto a = unpack_array(e, e.type);
        if (!a) return a.take_error();
        return Value(std::move(*a));
    }
    TypeDefinition var;
    var.base = DataTypes::varvalue_t;
    switch (e.type) {
        case DataTypes::string_t: {
            TypeDefinition s;
            s.base = DataTypes::string_t;
            return unpack(e, s, {});
        }
        case DataTypes::multidimarray_t: return unpack_multidim(e, nullptr);
        case DataTypes::list_t: var.container = ContainerKind::list; return unpack_container(e, var, {});
        case DataTypes::vector_t: var.container = ContainerKind::map_int32; return unpack_container(e, var, {});
        case DataTypes::dictionary_t: var.container = ContainerKind::map_string; return unpack_container(e, var, {});
        case DataTypes::structure_t:
        case DataTypes::pod_array_t:
        case DataTypes::pod_multidimarray_t:
        case DataTypes::namedarray_array_t:
        case DataTypes::namedarray_multidimarray_t: break;
        default: return err(MessageErrorType::DataTypeError, "unexpected " + element_type_text(e) + " for a varvalue");
    }
    if (lookup_) return unpack_var_typed(e);
    switch (e.type) {
        case DataTypes::structure_t: return unpack_struct_untyped(e);
        case DataTypes::pod_array_t: {
            auto p = unpack_pod_untyped(e);
            if (!p) return p.take_error();
            return Value(std::move(*p));
        }
        case DataTypes::namedarray_array_t: {
            auto a = unpack_namedarray_untyped(e);
            if (!a) return a.take_error();
            return Value(std::move(*a));
        }
        default: break;
    }
    // 111 / 116: dims + the 110 / 115 array, same type name.
    auto dims = unpack_dims(e);
    if (!dims) return dims.take_error();
    auto arr = child(e, "array");
    if (!arr) return arr.take_error();
    PathScope ps(path_, "array");
    bool pod = e.type == DataTypes::pod_multidimarray_t;
    DataTypes inner = pod ? DataTypes::pod_array_t : DataTypes::namedarray_array_t;
    if ((*arr)->type != inner || (*arr)->type_name != e.type_name)
        return err(MessageErrorType::DataTypeMismatch, "multi-dim array holds " + element_type_text(**arr));
    TypeDefinition any;
    any.array = ArrayKind::multidimarray;
    any.array_var_length = true;
    if (pod) {
        auto p = unpack_pod_untyped(**arr);
        if (!p) return p.take_error();
        if (auto r = check_dims(*dims, p->count, any); !r) return relay(r.error());
        p->dims = std::move(*dims);
        return Value(std::move(*p));
    }
    auto a = unpack_namedarray_untyped(**arr);
    if (!a) return a.take_error();
    a->dims = std::move(*dims);  // items per namedarray unknown without a robdef: dims are kept as sent
    return Value(std::move(*a));
}

// varvalue holding a named type: the element's type name picks the definition.
Result<Value> Unpacker::unpack_var_typed(const MessageElement& e) {
    TypeDefinition t;
    t.base = DataTypes::namedtype_t;
    t.type_name = e.type_name;
    t.qualified_name = e.type_name;
    if (e.type == DataTypes::pod_array_t || e.type == DataTypes::namedarray_array_t) {
        t.array = ArrayKind::array;
        t.array_var_length = true;
    } else if (e.type != DataTypes::structure_t) {
        t.array = ArrayKind::multidimarray;
        t.array_var_length = true;
    }
    auto nt = resolve_named_type(t, *lookup_, {});
    if (!nt) return relay(nt.error());
    bool ok = (e.type == DataTypes::structure_t && nt->kind == NamedTypeKind::structure) ||
              ((e.type == DataTypes::pod_array_t || e.type == DataTypes::pod_multidimarray_t) &&
               nt->kind == NamedTypeKind::pod) ||
              ((e.type == DataTypes::namedarray_array_t || e.type == DataTypes::namedarray_multidimarray_t) &&
               nt->kind == NamedTypeKind::namedarray);
    if (!ok)
        return err(MessageErrorType::DataTypeMismatch,
                   element_type_text(e) + " does not match the definition of " + nt->qualified_name);
    switch (nt->kind) {
        case NamedTypeKind::structure: return unpack_struct(e, t, *nt);
        case NamedTypeKind::pod: return unpack_pod(e, t, *nt);
        default: return unpack_namedarray(e, t, *nt);
    }
}

Result<Value> Unpacker::unpack_struct_untyped(const MessageElement& e) {
    Structure s{e.type_name, {}};
    s.fields.reserve(e.elements.size());
    for (const auto& c : e.elements) {
        PathScope ps(path_, c.name);
        if (c.number || s.find(c.name)) return err(MessageErrorType::DataTypeError, "bad or duplicate field name");
        auto v = unpack_var(c);
        if (!v) return v.take_error();
        s.fields.push_back(Field{c.name, std::move(*v)});
    }
    return Value(std::move(s));
}

Result<PodArray> Unpacker::unpack_pod_untyped(const MessageElement& e) {
    PodArray p;
    p.type_name = e.type_name;
    for (std::size_t i = 0; i < e.elements.size(); ++i) {
        PathScope pi(path_, static_cast<std::int64_t>(i));
        const MessageElement& item = e.elements[i];
        auto n = element_number(item);
        if (!n || static_cast<std::size_t>(*n) != i)
            return err(MessageErrorType::DataTypeError, "pod array items must be numbered 0..n-1 in order");
        if (item.type != DataTypes::pod_t)
            return err(MessageErrorType::DataTypeMismatch, "expected a pod item (109), got " + element_type_text(item));
        if (i == 0) {
            for (const auto& c : item.elements) {
                if (c.number || p.field_index(c.name) >= 0)
                    return err(MessageErrorType::DataTypeError, "bad or duplicate pod field name");
                p.field_names.push_back(c.name);
            }
            p.values.reserve(e.elements.size() * p.field_names.size());
        } else if (item.elements.size() != p.field_names.size()) {
            return err(MessageErrorType::DataTypeError, "pod items have different fields");
        }
        for (std::size_t j = 0; j < item.elements.size(); ++j) {
            const MessageElement& c = item.elements[j];
            if (c.number || c.name != p.field_names[j])
                return err(MessageErrorType::DataTypeError, "pod items have different fields");
            PathScope pf(path_, c.name);
            if (!is_numeric(c.type) && c.type != DataTypes::pod_array_t && c.type != DataTypes::namedarray_array_t)
                return err(MessageErrorType::DataTypeError, "pod fields must be numeric, pod or namedarray");
            auto v = unpack_var(c);
            if (!v) return v.take_error();
            p.values.push_back(std::move(*v));
        }
        ++p.count;
    }
    return p;
}

Result<NamedArray> Unpacker::unpack_namedarray_untyped(const MessageElement& e) {
    auto arr = child(e, "array");
    if (!arr) return arr.take_error();
    PathScope ps(path_, "array");
    if (!is_numeric((*arr)->type))
        return err(MessageErrorType::DataTypeMismatch, "namedarray data must be numeric, got " + element_type_text(**arr));
    auto a = unpack_array(**arr, (*arr)->type);
    if (!a) return a.take_error();
    return NamedArray{e.type_name, std::move(*a), {}};
}

}  // namespace

Result<Value> unpack_value(const MessageElement& element, const TypeDefinition& type,
                           const robdef::TypeLookup& lookup, std::string_view context_service, const Limits& limits) {
    Unpacker u(&lookup, element.name, limits.max_nesting_depth);
    return u.unpack(element, type, context_service);
}

Result<Value> unpack_value(const MessageElement& element, const TypeDefinition& type,
                           const robdef::TypeLookup& lookup, std::string_view context_service) {
    return unpack_value(element, type, lookup, context_service, Limits{});
}

Result<Value> unpack_value_untyped(const MessageElement& element, const Limits& limits) {
    Unpacker u(nullptr, element.name, limits.max_nesting_depth);
    return u.unpack_var(element);
}

}  // namespace rr
