// Value → MessageElement (see pack_value.hpp for the layouts and errors).
#include "core/value/pack_value.hpp"

#include <algorithm>

#include "core/value/element_layout.hpp"
#include "core/value/named_type.hpp"
#include "core/value/type_cache.hpp"
#include "core/value/value_path.hpp"
#include "core/value/var_type.hpp"

namespace rr {

using robdef::ArrayKind;
using robdef::ContainerKind;
using robdef::NamedTypeKind;
using robdef::TypeDefinition;

namespace {

class Packer {
public:
    Packer(const robdef::TypeLookup& lookup, std::string_view root, std::size_t max_depth)
        : lookup_(lookup), cache_(lookup), path_(root), max_depth_(max_depth) {}

    Result<MessageElement> pack(const Value& v, const TypeDefinition& t, std::string_view ctx);

private:
    struct Depth {
        explicit Depth(std::size_t& d) : d_(d) { ++d_; }
        ~Depth() { --d_; }
        std::size_t& d_;
    };

    Unexpected err(MessageErrorType type, std::string_view msg) const { return path_.error(type, msg); }
    Unexpected expected(const TypeDefinition& t, std::string_view qualified, const Value& v) const {
        std::string got(value_kind_name(v.kind()));
        if (auto* a = v.get_if<NumericArray>()) got = std::string(data_type_keyword(a->type())) + " " + got;
        return err(v.is_null() ? MessageErrorType::NullValue : MessageErrorType::DataTypeMismatch,
                   "expected " + type_text(t, qualified) + ", got " + got);
    }
    Result<void> check_type_name(const std::string& have, const NamedType& nt) const {
        if (!have.empty() && have != nt.qualified_name)
            return err(MessageErrorType::DataTypeMismatch,
                       "expected type " + nt.qualified_name + ", got " + have);
        return {};
    }

    Result<MessageElement> pack_container(const Value& v, const TypeDefinition& t, std::string_view ctx);
    Result<MessageElement> pack_numeric(const Value& v, const TypeDefinition& t);
    Result<MessageElement> pack_named(const Value& v, const TypeDefinition& t, std::string_view ctx);
    Result<MessageElement> pack_struct(const Value& v, const TypeDefinition& t, const NamedType& nt);
    Result<MessageElement> pack_pod(const Value& v, const TypeDefinition& t, const NamedType& nt);
    Result<MessageElement> pack_pod_items(const PodArray& p, const TypeDefinition& t, const NamedType& nt);
    Result<MessageElement> pack_pod_field(const Value& v, const PodFieldPlan& plan);
    Result<MessageElement> pack_namedarray(const Value& v, const TypeDefinition& t, const NamedType& nt);
    Result<MessageElement> pack_namedarray_items(const NamedArray& a, const TypeDefinition& t,
                                                 const NamedType& nt, std::size_t* items_out = nullptr);
    Result<MessageElement> pack_var(const Value& v);

    const robdef::TypeLookup& lookup_;
    TypeCache cache_;
    ValuePath path_;
    std::size_t depth_ = 0;
    std::size_t max_depth_;
};

Result<MessageElement> Packer::pack(const Value& v, const TypeDefinition& t, std::string_view ctx) {
    Depth d(depth_);
    if (depth_ > max_depth_) return err(MessageErrorType::ProtocolError, "value nested too deeply");
    if (t.container != ContainerKind::none) return pack_container(v, t, ctx);
    if (is_numeric(t.base)) return pack_numeric(v, t);
    switch (t.base) {
        case DataTypes::void_t:
            if (!v.is_null()) return err(MessageErrorType::DataTypeMismatch, "expected void (null)");
            return void_element();
        case DataTypes::string_t: {
            if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "string arrays are not allowed");
            auto* s = v.get_if<std::string>();
            if (!s) return expected(t, {}, v);
            return string_element(*s);
        }
        case DataTypes::varvalue_t:
            if (t.array != ArrayKind::none)
                return err(MessageErrorType::DataTypeError, "varvalue arrays are not supported");
            return pack_var(v);
        case DataTypes::namedtype_t: return pack_named(v, t, ctx);
        default:
            return err(MessageErrorType::DataTypeError, "\"" + t.to_string() + "\" is not a value type");
    }
}

Result<MessageElement> Packer::pack_container(const Value& v, const TypeDefinition& t, std::string_view ctx) {
    if (t.container == ContainerKind::generator)
        return err(MessageErrorType::DataTypeError, "a generator is not a value type");
    if (v.is_null()) return void_element();
    TypeDefinition item_type = without_container(t);
    MessageElement e;
    switch (t.container) {
        case ContainerKind::list: {
            auto* l = v.get_if<List>();
            if (!l) return expected(t, {}, v);
            if (l->items.size() > 0x7fffffffu) return err(MessageErrorType::DataTypeError, "list too long");
            e.type = DataTypes::list_t;
            e.elements.reserve(l->items.size());
            for (std::size_t i = 0; i < l->items.size(); ++i) {
                PathScope ps(path_, static_cast<std::int64_t>(i));
                auto c = pack(l->items[i], item_type, ctx);
                if (!c) return c.take_error();
                c->number = static_cast<std::int32_t>(i);
                e.elements.push_back(std::move(*c));
            }
            return e;
        }
        case ContainerKind::map_int32: {
            auto* m = v.get_if<MapInt32>();
            if (!m) return expected(t, {}, v);
            e.type = DataTypes::vector_t;
            e.elements.reserve(m->entries.size());
            for (const auto& [key, item] : m->entries) {
                PathScope ps(path_, key);
                for (const auto& prev : e.elements)
                    if (*prev.number == key) return err(MessageErrorType::DataTypeError, "duplicate map key");
                auto c = pack(item, item_type, ctx);
                if (!c) return c.take_error();
                c->number = key;
                e.elements.push_back(std::move(*c));
            }
            return e;
        }
        case ContainerKind::map_string: {
            auto* m = v.get_if<MapString>();
            if (!m) return expected(t, {}, v);
            e.type = DataTypes::dictionary_t;
            e.elements.reserve(m->entries.size());
            for (const auto& [key, item] : m->entries) {
                PathScope ps(path_, PathScope::Key{key});
                for (const auto& prev : e.elements)
                    if (prev.name == key) return err(MessageErrorType::DataTypeError, "duplicate map key");
                auto c = pack(item, item_type, ctx);
                if (!c) return c.take_error();
                c->name = key;
                e.elements.push_back(std::move(*c));
            }
            return e;
        }
        default: return err(MessageErrorType::DataTypeError, "unknown container");
    }
}

Result<MessageElement> Packer::pack_numeric(const Value& v, const TypeDefinition& t) {
    if (t.array == ArrayKind::multidimarray) {
        auto* m = v.get_if<MultiDimArray>();
        if (!m) return expected(t, {}, v);
        if (m->array.type() != t.base) return expected(t, {}, Value(m->array));
        if (auto r = check_dims(m->dims, m->array.size(), t); !r) return err(r.error().type, r.error().message);
        return multidim_element(m->dims, array_element("array", m->array));
    }
    auto* a = v.get_if<NumericArray>();
    if (!a || a->type() != t.base) return expected(t, {}, v);
    if (auto r = check_count(a->size(), t); !r) return err(r.error().type, r.error().message);
    return array_element({}, *a);
}

Result<MessageElement> Packer::pack_named(const Value& v, const TypeDefinition& t, std::string_view ctx) {
    auto nt = resolve_named_type(t, lookup_, ctx);
    if (!nt) return err(nt.error().type, nt.error().message);
    switch (nt->kind) {
        case NamedTypeKind::structure: return pack_struct(v, t, *nt);
        case NamedTypeKind::pod: return pack_pod(v, t, *nt);
        case NamedTypeKind::namedarray: return pack_namedarray(v, t, *nt);
        case NamedTypeKind::enumeration: {
            if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "enum arrays are not allowed");
            std::int32_t value = 0;
            if (auto* e = v.get_if<Enum>()) {
                if (auto r = check_type_name(e->type_name, *nt); !r) return r.take_error();
                value = e->value;
            } else if (auto* a = v.get_if<NumericArray>(); a && a->type() == DataTypes::int32_t && a->size() == 1) {
                value = a->at<std::int32_t>(0);
            } else {
                return expected(t, nt->qualified_name, v);
            }
            return array_element({}, NumericArray::scalar(value));
        }
        default:
            return err(MessageErrorType::DataTypeError, "\"" + nt->qualified_name + "\" is not a value type");
    }
}

Result<MessageElement> Packer::pack_struct(const Value& v, const TypeDefinition& t, const NamedType& nt) {
    if (t.array != ArrayKind::none) return err(MessageErrorType::DataTypeError, "struct arrays are not allowed");
    if (v.is_null()) return void_element();
    auto* s = v.get_if<Structure>();
    if (!s) return expected(t, nt.qualified_name, v);
    if (auto r = check_type_name(s->type_name, nt); !r) return r.take_error();
    MessageElement e;
    e.type = DataTypes::structure_t;
    e.type_name = nt.qualified_name;
    e.elements.reserve(nt.entry->members.size());
    std::size_t matched = 0;
    for (const auto& m : nt.entry->members) {
        if (m.kind != robdef::MemberKind::field) continue;
        PathScope ps(path_, m.name);
        const Value* fv = s->find(m.name);
        if (!fv) return err(MessageErrorType::DataTypeError, "missing field of " + nt.qualified_name);
        ++matched;
        auto c = pack(*fv, m.type, nt.service->name);
        if (!c) return c.take_error();
        c->name = m.name;
        e.elements.push_back(std::move(*c));
    }
    if (matched != s->fields.size()) {
        for (const auto& f : s->fields) {
            const auto* m = nt.entry->find_member(f.name);
            if (!m || m->kind != robdef::MemberKind::field) {
                PathScope ps(path_, f.name);
                return err(MessageErrorType::DataTypeError, "unknown field of " + nt.qualified_name);
            }
        }
        return err(MessageErrorType::DataTypeError, "duplicate field in " + nt.qualified_name);
    }
    return e;
}

Result<MessageElement> Packer::pack_pod(const Value& v, const TypeDefinition& t, const NamedType& nt) {
    auto* p = v.get_if<PodArray>();
    if (!p) return expected(t, nt.qualified_name, v);
    if (auto r = check_type_name(p->type_name, nt); !r) return r.take_error();
    if (t.array == ArrayKind::multidimarray) {
        if (p->dims.empty()) return err(MessageErrorType::DataTypeError, "expected a multi-dim pod array (dims)");
        if (auto r = check_dims(p->dims, p->count, t); !r) return err(r.error().type, r.error().message);
        TypeDefinition flat = t;
        flat.array = ArrayKind::array;
        flat.array_var_length = true;
        flat.array_length.clear();
        auto inner = pack_pod_items(*p, flat, nt);
        if (!inner) return inner;
        inner->name = "array";
        MessageElement e = multidim_element(p->dims, std::move(*inner));
        e.type = DataTypes::pod_multidimarray_t;
        e.type_name = nt.qualified_name;
        return e;
    }
    if (!p->dims.empty()) return err(MessageErrorType::DataTypeError, "multi-dim pod array where " + type_text(t, nt.qualified_name) + " expected");
    return pack_pod_items(*p, t, nt);
}

Result<MessageElement> Packer::pack_pod_items(const PodArray& p, const TypeDefinition& t, const NamedType& nt) {
    if (auto r = check_count(p.count, t); !r) return err(r.error().type, r.error().message);
    auto cached = cache_.pod_plans(nt);
    if (!cached) return err(cached.error().type, cached.error().message);
    const std::vector<PodFieldPlan>& plans = **cached;
    const std::size_t nf = p.field_names.size();
    if (p.values.size() != p.count * nf)
        return err(MessageErrorType::DataTypeError, "pod value holds " + std::to_string(p.values.size()) +
                                                        " field values for " + std::to_string(p.count) + " items");
    // Where each definition field sits in the value's field order.
    std::vector<std::size_t> index(plans.size());
    for (std::size_t k = 0; k < plans.size(); ++k) {
        auto at = p.field_index(plans[k].member->name);
        if (at < 0) {
            PathScope ps(path_, plans[k].member->name);
            return err(MessageErrorType::DataTypeError, "missing field of " + nt.qualified_name);
        }
        index[k] = static_cast<std::size_t>(at);
    }
    if (plans.size() != nf) {
        for (const auto& name : p.field_names) {
            if (std::none_of(plans.begin(), plans.end(), [&](auto& pl) { return pl.member->name == name; })) {
                PathScope ps(path_, name);
                return err(MessageErrorType::DataTypeError, "unknown field of " + nt.qualified_name);
            }
        }
        return err(MessageErrorType::DataTypeError, "duplicate field in " + nt.qualified_name);
    }
    MessageElement e;
    e.type = DataTypes::pod_array_t;
    e.type_name = nt.qualified_name;
    e.elements.reserve(p.count);
    for (std::size_t i = 0; i < p.count; ++i) {
        PathScope pi(path_, static_cast<std::int64_t>(i));
        MessageElement item;
        item.number = static_cast<std::int32_t>(i);
        item.type = DataTypes::pod_t;
        item.elements.reserve(plans.size());
        for (std::size_t k = 0; k < plans.size(); ++k) {
            const PodFieldPlan& plan = plans[k];
            PathScope pf(path_, plan.member->name);
            const Value& fv = p.values[i * nf + index[k]];
            auto c = pack_pod_field(fv, plan);
            if (!c) return c.take_error();
            c->name = plan.member->name;
            item.elements.push_back(std::move(*c));
        }
        e.elements.push_back(std::move(item));
    }
    return e;
}

Result<MessageElement> Packer::pack_pod_field(const Value& v, const PodFieldPlan& plan) {
    Depth d(depth_);
    if (depth_ > max_depth_) return err(MessageErrorType::ProtocolError, "value nested too deeply");
    const TypeDefinition& wt = plan.wire_type;
    if (!plan.multidim) {
        if (wt.base == DataTypes::namedtype_t) {
            if (plan.named.kind == NamedTypeKind::pod) return pack_pod(v, wt, plan.named);
            return pack_namedarray(v, wt, plan.named);
        }
        return pack_numeric(v, wt);
    }
    // Multi-dim field: the dims must be the declared ones, then the items travel flat.
    const TypeDefinition& decl = plan.member->type;
    auto check = [&](const std::vector<std::uint32_t>& dims, std::size_t n) -> Result<void> {
        if (dims.empty()) return {};  // already flat: the count check below applies
        if (auto r = check_dims(dims, n, decl); !r) return err(r.error().type, r.error().message);
        return {};
    };
    if (is_numeric(wt.base)) {
        if (auto* m = v.get_if<MultiDimArray>()) {
            if (m->array.type() != wt.base) return expected(decl, {}, Value(m->array));
            if (auto r = check(m->dims, m->array.size()); !r) return r.take_error();
            if (auto r = check_count(m->array.size(), wt); !r) return err(r.error().type, r.error().message);
            return array_element({}, m->array);
        }
        return pack_numeric(v, wt);
    }
    if (plan.named.kind == NamedTypeKind::pod) {
        auto* p = v.get_if<PodArray>();
        if (!p) return expected(decl, plan.named.qualified_name, v);
        if (auto r = check_type_name(p->type_name, plan.named); !r) return r.take_error();
        if (auto r = check(p->dims, p->count); !r) return r.take_error();
        return pack_pod_items(*p, wt, plan.named);
    }
    auto* a = v.get_if<NamedArray>();
    if (!a) return expected(decl, plan.named.qualified_name, v);
    if (auto r = check_type_name(a->type_name, plan.named); !r) return r.take_error();
    std::size_t items = 0;
    auto e = pack_namedarray_items(*a, wt, plan.named, &items);
    if (!e) return e;
    if (auto r = check(a->dims, items); !r) return r.take_error();
    return e;
}

Result<MessageElement> Packer::pack_namedarray(const Value& v, const TypeDefinition& t, const NamedType& nt) {
    auto* a = v.get_if<NamedArray>();
    if (!a) return expected(t, nt.qualified_name, v);
    if (auto r = check_type_name(a->type_name, nt); !r) return r.take_error();
    if (t.array == ArrayKind::multidimarray) {
        if (a->dims.empty())
            return err(MessageErrorType::DataTypeError, "expected a multi-dim namedarray array (dims)");
        TypeDefinition flat = t;
        flat.array = ArrayKind::array;
        flat.array_var_length = true;
        flat.array_length.clear();
        std::size_t items = 0;
        auto inner = pack_namedarray_items(*a, flat, nt, &items);
        if (!inner) return inner;
        if (auto r = check_dims(a->dims, items, t); !r) return err(r.error().type, r.error().message);
        inner->name = "array";
        MessageElement e = multidim_element(a->dims, std::move(*inner));
        e.type = DataTypes::namedarray_multidimarray_t;
        e.type_name = nt.qualified_name;
        return e;
    }
    if (!a->dims.empty())
        return err(MessageErrorType::DataTypeError,
                   "multi-dim namedarray where " + type_text(t, nt.qualified_name) + " expected");
    return pack_namedarray_items(*a, t, nt);
}

Result<MessageElement> Packer::pack_namedarray_items(const NamedArray& a, const TypeDefinition& t,
                                                     const NamedType& nt, std::size_t* items_out) {
    auto layout = cache_.layout(nt);
    if (!layout) return err(layout.error().type, layout.error().message);
    if (a.array.type() != layout->element_type)
        return err(MessageErrorType::DataTypeMismatch,
                   "namedarray " + nt.qualified_name + " stores " +
                       std::string(data_type_keyword(layout->element_type)) + ", got " +
                       std::string(data_type_keyword(a.array.type())));
    if (a.array.size() % layout->elements_per_item != 0)
        return err(MessageErrorType::DataTypeError,
                   "namedarray data length " + std::to_string(a.array.size()) + " is not a multiple of " +
                       std::to_string(layout->elements_per_item));
    std::size_t items = a.array.size() / layout->elements_per_item;
    if (auto r = check_count(items, t); !r) return err(r.error().type, r.error().message);
    if (items_out) *items_out = items;
    MessageElement e;
    e.type = DataTypes::namedarray_array_t;
    e.type_name = nt.qualified_name;
    e.elements.push_back(array_element("array", a.array));
    return e;
}

Result<MessageElement> Packer::pack_var(const Value& v) {
    // A varvalue travels as its concrete type: build that type and pack with it.
    TypeDefinition t;
    switch (v.kind()) {
        case ValueKind::null: return void_element();
        case ValueKind::numeric:
            t.base = v.get_if<NumericArray>()->type();
            t.array = ArrayKind::array;
            t.array_var_length = true;
            break;
        case ValueKind::multidim:
            t.base = v.get_if<MultiDimArray>()->array.type();
            t.array = ArrayKind::multidimarray;
            t.array_var_length = true;
            break;
        case ValueKind::string: t.base = DataTypes::string_t; break;
        case ValueKind::structure:
        case ValueKind::pod:
        case ValueKind::namedarray:
        case ValueKind::enumeration: {
            std::string name = var_type_string(v);
            if (v.kind() == ValueKind::enumeration && v.get_if<Enum>()->type_name.empty()) {
                t.base = DataTypes::int32_t;
                return pack(Value(NumericArray::scalar(v.get_if<Enum>()->value)), t, {});
            }
            if (name.empty() || name[0] == '[')
                return err(MessageErrorType::DataTypeError, "varvalue holds a named value without a type name");
            auto parsed = parse_type_string(name);
            if (!parsed) return err(parsed.error().type, parsed.error().message);
            t = std::move(*parsed);
            t.qualified_name = t.type_name;
            break;
        }
        case ValueKind::map_int32:
        case ValueKind::map_string:
        case ValueKind::list:
            t.base = DataTypes::varvalue_t;
            t.container = v.kind() == ValueKind::list        ? ContainerKind::list
                          : v.kind() == ValueKind::map_int32 ? ContainerKind::map_int32
                                                             : ContainerKind::map_string;
            break;
    }
    return pack(v, t, {});
}

}  // namespace

Result<MessageElement> pack_value(const Value& value, const TypeDefinition& type, std::string_view element_name,
                                  const robdef::TypeLookup& lookup, std::string_view context_service,
                                  const Limits& limits) {
    Packer p(lookup, element_name, limits.max_nesting_depth);
    auto e = p.pack(value, type, context_service);
    if (e) e->name = std::string(element_name);
    return e;
}

Result<MessageElement> pack_value(const Value& value, const TypeDefinition& type, std::string_view element_name,
                                  const robdef::TypeLookup& lookup, std::string_view context_service) {
    return pack_value(value, type, element_name, lookup, context_service, Limits{});
}

}  // namespace rr
