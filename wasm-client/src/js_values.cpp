// RR values <-> JavaScript values (js_values.hpp).
#include "wasm-client/src/js_values.hpp"

#include <string>
#include <vector>

#include "core/json/namedarray_shape.hpp"
#include "core/value/element_layout.hpp"
#include "core/value/named_type.hpp"
#include "core/value/var_type.hpp"
#include "wasm-client/src/js_numbers.hpp"

namespace rr::wasm {

using emscripten::val;
using robdef::ArrayKind;
using robdef::ContainerKind;
using robdef::NamedTypeKind;
using robdef::TypeDefinition;

namespace {

bool is_complex_type(DataTypes t) { return t == DataTypes::cdouble_t || t == DataTypes::csingle_t; }

class Converter {
public:
    Converter(const robdef::TypeLookup& lookup) : lookup_(lookup) {}

    Result<val> to(const Value& v, const TypeDefinition& t, std::string_view ctx, int depth = 0);
    Result<Value> from(const val& v, const TypeDefinition& t, std::string_view ctx, int depth = 0);

private:
    static constexpr int kMaxDepth = 64;

    Result<val> named_to(const Value& v, const TypeDefinition& t, std::string_view ctx, int depth);
    val js_shape(const NamedArrayShape& shape);
    Result<Value> named_from(const val& v, const TypeDefinition& t, std::string_view ctx, int depth);
    Result<void> namedarray_item_from(const val& obj, NumericArray& flat, std::size_t& off, const NamedArrayShape& shape);
    /// The fields of a struct / pod, in definition order.
    static std::vector<const robdef::MemberDefinition*> struct_fields(const NamedType& nt);

    const robdef::TypeLookup& lookup_;
    NamedArrayShapeCache shapes_;
    std::vector<std::pair<const NamedArrayShape*, val>> js_shapes_;
};

std::vector<const robdef::MemberDefinition*> Converter::struct_fields(const NamedType& nt) {
    std::vector<const robdef::MemberDefinition*> out;
    for (const auto& m : nt.entry->members)
        if (m.kind == robdef::MemberKind::field) out.push_back(&m);
    return out;
}

Result<val> Converter::to(const Value& v, const TypeDefinition& t, std::string_view ctx, int depth) {
    if (depth > kMaxDepth) return fail(MessageErrorType::ProtocolError, "value nested too deeply");
    if (t.container != ContainerKind::none) {
        if (v.is_null()) return val::null();
        TypeDefinition item = without_container(t);
        if (auto* l = v.get_if<List>()) {
            val arr = val::array();
            for (std::size_t i = 0; i < l->items.size(); ++i) {
                auto x = to(l->items[i], item, ctx, depth + 1);
                if (!x) return x.take_error();
                arr.set(i, *x);
            }
            return arr;
        }
        if (auto* m = v.get_if<MapString>()) {
            val obj = val::object();
            for (const auto& [k, x] : m->entries) {
                auto j = to(x, item, ctx, depth + 1);
                if (!j) return j.take_error();
                obj.set(u8(k), *j);
            }
            return obj;
        }
        if (auto* m = v.get_if<MapInt32>()) {
            val map = val::global("Map").new_();
            for (const auto& [k, x] : m->entries) {
                auto j = to(x, item, ctx, depth + 1);
                if (!j) return j.take_error();
                map.call<void>("set", k, *j);
            }
            return map;
        }
        return fail(MessageErrorType::DataTypeMismatch, "expected a container for " + t.to_string());
    }
    if (t.base == DataTypes::varvalue_t && t.array == ArrayKind::none) {
        if (v.is_null()) return val::null();
        std::string type = var_type_string(v);
        auto vt = parse_type_string(type);
        if (!vt) return vt.take_error();
        auto inner = to(v, *vt, ctx, depth + 1);
        if (!inner) return inner.take_error();
        val o = val::object();
        o.set("type", u8(type));
        o.set("value", *inner);
        return o;
    }
    if (t.base == DataTypes::string_t) {
        auto* s = v.get_if<std::string>();
        if (!s) return fail(MessageErrorType::DataTypeMismatch, "expected a string value");
        return u8(*s);
    }
    if (is_numeric(t.base)) {
        if (t.array == ArrayKind::multidimarray) {
            auto* m = v.get_if<MultiDimArray>();
            if (!m) return fail(MessageErrorType::DataTypeMismatch, "expected a multi-dim array for " + t.to_string());
            val o = val::object();
            o.set("dims", dims_to_js(m->dims));
            o.set("array", numeric_array_to_js(m->array));
            return o;
        }
        auto* a = v.get_if<NumericArray>();
        if (!a) return fail(MessageErrorType::DataTypeMismatch, "expected a numeric value for " + t.to_string());
        if (t.array == ArrayKind::array) return numeric_array_to_js(*a);
        if (a->size() != 1) return fail(MessageErrorType::DataTypeError, "expected one item for " + t.to_string());
        return numeric_scalar_to_js(*a);
    }
    if (t.base == DataTypes::namedtype_t) return named_to(v, t, ctx, depth);
    if (t.is_void()) return val::null();
    return fail(MessageErrorType::DataTypeError, "no JS form for type " + t.to_string());
}

Result<val> Converter::named_to(const Value& v, const TypeDefinition& t, std::string_view ctx, int depth) {
    auto nt = resolve_named_type(t, lookup_, ctx);
    if (!nt) return nt.take_error();
    std::string_view svc = nt->service->name;
    switch (nt->kind) {
        case NamedTypeKind::enumeration: {
            if (auto* e = v.get_if<Enum>()) return val(e->value);
            auto x = v.as<std::int32_t>();
            if (!x) return x.take_error();
            return val(*x);
        }
        case NamedTypeKind::structure: {
            if (v.is_null()) return val::null();
            auto* s = v.get_if<Structure>();
            if (!s) return fail(MessageErrorType::DataTypeMismatch, "expected a struct for " + nt->qualified_name);
            val o = val::object();
            for (const auto* m : struct_fields(*nt)) {
                const Value* f = s->find(m->name);
                if (!f) return fail(MessageErrorType::MessageElementNotFound, "struct field " + m->name + " missing");
                auto j = to(*f, m->type, svc, depth + 1);
                if (!j) return j.take_error();
                o.set(m->name, *j);
            }
            return o;
        }
        case NamedTypeKind::pod: {
            auto* p = v.get_if<PodArray>();
            if (!p) return fail(MessageErrorType::DataTypeMismatch, "expected a pod for " + nt->qualified_name);
            std::vector<const robdef::MemberDefinition*> defs;
            for (const auto& name : p->field_names) {
                const auto* m = nt->entry->find_member(name);
                if (!m) return fail(MessageErrorType::DataTypeError, "pod field " + name + " not in " + nt->qualified_name);
                defs.push_back(m);
            }
            val items = val::array();
            for (std::size_t i = 0; i < p->count; ++i) {
                val o = val::object();
                for (std::size_t j = 0; j < defs.size(); ++j) {
                    auto x = to(p->values[i * defs.size() + j], defs[j]->type, svc, depth + 1);
                    if (!x) return x.take_error();
                    o.set(defs[j]->name, *x);
                }
                items.set(i, o);
            }
            if (t.array == ArrayKind::none) {
                if (p->count != 1) return fail(MessageErrorType::DataTypeError, "expected one pod");
                return items[0];
            }
            if (t.array == ArrayKind::multidimarray) {
                val o = val::object();
                o.set("dims", dims_to_js(p->dims.empty() ? std::vector<std::uint32_t>{static_cast<std::uint32_t>(p->count)} : p->dims));
                o.set("array", items);
                return o;
            }
            return items;
        }
        case NamedTypeKind::namedarray: {
            auto* n = v.get_if<NamedArray>();
            if (!n) return fail(MessageErrorType::DataTypeMismatch, "expected a namedarray for " + nt->qualified_name);
            auto shape = shapes_.get(*nt, lookup_);
            if (!shape) return shape.take_error();
            const NamedArrayShape& s = **shape;
            if (s.width == 0 || n->array.size() % s.width != 0)
                return fail(MessageErrorType::DataTypeError, "namedarray data does not fit " + nt->qualified_name);
            std::size_t count = n->array.size() / s.width;
            val flat = typed_array_copy(n->array);
            // the items built in JS in one call (namedarray_items.js): per-field embind calls cost ~10 µs a point
            val items = val::module_property("rrNamedArrayItems")(flat, js_shape(s), count, is_complex_type(s.element_type));
            if (t.array == ArrayKind::none) {
                if (count != 1) return fail(MessageErrorType::DataTypeError, "expected one namedarray");
                return items[0];
            }
            if (t.array == ArrayKind::multidimarray) {
                val o = val::object();
                o.set("dims", dims_to_js(n->dims.empty() ? std::vector<std::uint32_t>{static_cast<std::uint32_t>(count)} : n->dims));
                o.set("array", items);
                return o;
            }
            return items;
        }
        default:
            return fail(MessageErrorType::DataTypeError, "no JS form for " + nt->qualified_name);
    }
}

/// `shape` as namedarray_items.js reads it: [[name, count, array, nested shape or null], ...], made once per shape.
val Converter::js_shape(const NamedArrayShape& shape) {
    for (const auto& [p, v] : js_shapes_)
        if (p == &shape) return v;
    val members = val::array();
    for (std::size_t i = 0; i < shape.members.size(); ++i) {
        const auto& m = shape.members[i];
        val e = val::array();
        e.set(0, u8(std::string(m.name)));
        e.set(1, m.count);
        e.set(2, m.array);
        e.set(3, m.nested ? js_shape(*m.nested) : val::null());
        members.set(i, e);
    }
    js_shapes_.emplace_back(&shape, members);
    return members;
}

Result<Value> Converter::from(const val& v, const TypeDefinition& t, std::string_view ctx, int depth) {
    if (depth > kMaxDepth) return fail(MessageErrorType::ProtocolError, "value nested too deeply");
    if (t.container != ContainerKind::none) {
        if (is_nullish(v)) return Value();
        TypeDefinition item = without_container(t);
        if (t.container == ContainerKind::list) {
            if (!val::global("Array").call<bool>("isArray", v)) return mismatch(v, "an array for " + t.to_string());
            List l;
            std::size_t n = v["length"].as<std::size_t>();
            for (std::size_t i = 0; i < n; ++i) {
                auto x = from(v[i], item, ctx, depth + 1);
                if (!x) return x.take_error();
                l.items.push_back(std::move(*x));
            }
            return Value(std::move(l));
        }
        if (t.container == ContainerKind::map_int32) {
            // A Map with number keys, or a plain object with decimal keys.
            val entries = v.instanceof(val::global("Map")) ? val::global("Array").call<val>("from", v.call<val>("entries"))
                                                            : val::global("Object").call<val>("entries", v);
            MapInt32 m;
            std::size_t n = entries["length"].as<std::size_t>();
            for (std::size_t i = 0; i < n; ++i) {
                val kv = entries[i];
                val key = kv[0];
                if (key.typeOf().as<std::string>() == "string") key = val::global("Number")(key);
                auto k = int32_from_js(key, "int32 map key");
                if (!k) return k.take_error();
                auto x = from(kv[1], item, ctx, depth + 1);
                if (!x) return x.take_error();
                m.entries.emplace_back(*k, std::move(*x));
            }
            return Value(std::move(m));
        }
        if (t.container == ContainerKind::map_string) {
            if (!is_object(v)) return mismatch(v, "an object for " + t.to_string());
            val entries = v.instanceof(val::global("Map")) ? val::global("Array").call<val>("from", v.call<val>("entries"))
                                                            : val::global("Object").call<val>("entries", v);
            MapString m;
            std::size_t n = entries["length"].as<std::size_t>();
            for (std::size_t i = 0; i < n; ++i) {
                val kv = entries[i];
                if (kv[0].typeOf().as<std::string>() != "string") return mismatch(kv[0], "a string map key");
                auto x = from(kv[1], item, ctx, depth + 1);
                if (!x) return x.take_error();
                m.entries.emplace_back(kv[0].as<std::string>(), std::move(*x));
            }
            return Value(std::move(m));
        }
        return fail(MessageErrorType::DataTypeError, "no value of type " + t.to_string());
    }
    if (t.base == DataTypes::varvalue_t && t.array == ArrayKind::none) {
        if (is_nullish(v)) return Value();
        if (is_object(v) && v["type"].typeOf().as<std::string>() == "string" && v.call<bool>("hasOwnProperty", std::string("value"))) {
            auto vt = parse_type_string(v["type"].as<std::string>());
            if (!vt) return vt.take_error();
            return from(v["value"], *vt, ctx, depth + 1);
        }
        // A bare JS value: only where its RR type is obvious.
        auto jt = js_type(v);
        if (jt == "string") return Value(v.as<std::string>());
        if (jt == "number") return Value(NumericArray::scalar<double>(v.as<double>()));
        if (auto dt = typed_array_type(v)) {
            auto a = array_from_js(v, *dt);
            if (!a) return a.take_error();
            return Value(std::move(*a));
        }
        return mismatch(v, "{type, value} for varvalue");
    }
    if (t.base == DataTypes::string_t) {
        if (v.typeOf().as<std::string>() != "string") return mismatch(v, "a string");
        return Value(v.as<std::string>());
    }
    if (is_numeric(t.base)) {
        if (t.array == ArrayKind::multidimarray) {
            if (!is_object(v)) return mismatch(v, "{dims, array} for " + t.to_string());
            auto dims = dims_from_js(v["dims"]);
            if (!dims) return dims.take_error();
            auto a = array_from_js(v["array"], t.base);
            if (!a) return a.take_error();
            return Value(MultiDimArray{std::move(*dims), std::move(*a)});
        }
        if (t.array == ArrayKind::array) {
            auto a = array_from_js(v, t.base);
            if (!a) return a.take_error();
            return Value(std::move(*a));
        }
        auto a = scalar_from_js(v, t.base);
        if (!a) return a.take_error();
        return Value(std::move(*a));
    }
    if (t.base == DataTypes::namedtype_t) return named_from(v, t, ctx, depth);
    if (t.is_void()) return Value();
    return fail(MessageErrorType::DataTypeError, "no value of type " + t.to_string());
}

Result<Value> Converter::named_from(const val& v, const TypeDefinition& t, std::string_view ctx, int depth) {
    auto nt = resolve_named_type(t, lookup_, ctx);
    if (!nt) return nt.take_error();
    std::string_view svc = nt->service->name;
    // Items of a pod / namedarray value: one object, an array of objects, or {dims, array}.
    std::vector<std::uint32_t> dims;
    auto items_of = [&](const val& x) -> Result<std::vector<val>> {
        std::vector<val> items;
        if (t.array == ArrayKind::none) {
            items.push_back(x);
            return items;
        }
        val arr = x;
        if (t.array == ArrayKind::multidimarray) {
            if (!is_object(x)) return mismatch(x, "{dims, array} for " + t.to_string());
            auto d = dims_from_js(x["dims"]);
            if (!d) return d.take_error();
            dims = std::move(*d);
            arr = x["array"];
        }
        if (!val::global("Array").call<bool>("isArray", arr)) return mismatch(arr, "an array of objects for " + t.to_string());
        std::size_t n = arr["length"].as<std::size_t>();
        for (std::size_t i = 0; i < n; ++i) items.push_back(arr[i]);
        return items;
    };
    switch (nt->kind) {
        case NamedTypeKind::enumeration: {
            if (v.typeOf().as<std::string>() == "string") {
                auto name = v.as<std::string>();
                for (const auto& ev : nt->enumeration->values)
                    if (ev.name == name) return Value(Enum{nt->qualified_name, ev.value});
                return fail(MessageErrorType::InvalidArgument, "\"" + name + "\" is not a value of " + nt->qualified_name);
            }
            auto x = int32_from_js(v, nt->qualified_name);
            if (!x) return x.take_error();
            return Value(Enum{nt->qualified_name, *x});
        }
        case NamedTypeKind::structure: {
            if (is_nullish(v)) return Value();
            if (!is_object(v)) return mismatch(v, "an object for " + nt->qualified_name);
            Structure s{nt->qualified_name, {}};
            for (const auto* m : struct_fields(*nt)) {
                auto f = from(v[m->name], m->type, svc, depth + 1);
                if (!f) return fail(f.error().type, "field " + m->name + ": " + f.error().message);
                s.fields.push_back(Field{m->name, std::move(*f)});
            }
            return Value(std::move(s));
        }
        case NamedTypeKind::pod: {
            auto items = items_of(v);
            if (!items) return items.take_error();
            auto defs = struct_fields(*nt);
            std::vector<std::string> names;
            for (const auto* m : defs) names.push_back(m->name);
            PodArray p(nt->qualified_name, std::move(names));
            for (const auto& item : *items) {
                if (!is_object(item)) return mismatch(item, "an object for pod " + nt->qualified_name);
                std::vector<Value> fvals;
                for (const auto* m : defs) {
                    auto f = from(item[m->name], m->type, svc, depth + 1);
                    if (!f) return fail(f.error().type, "field " + m->name + ": " + f.error().message);
                    fvals.push_back(std::move(*f));
                }
                if (auto r = p.push_back(std::move(fvals)); !r) return r.take_error();
            }
            p.dims = dims;
            return Value(std::move(p));
        }
        case NamedTypeKind::namedarray: {
            auto shape = shapes_.get(*nt, lookup_);
            if (!shape) return shape.take_error();
            const NamedArrayShape& s = **shape;
            if (t.array == ArrayKind::array && is_typed_array(v)) {  // flat form
                auto a = array_from_js(v, s.element_type);
                if (!a) return a.take_error();
                return Value(NamedArray{nt->qualified_name, std::move(*a), {}});
            }
            auto items = items_of(v);
            if (!items) return items.take_error();
            NumericArray flat = NumericArray::zeros(s.element_type, items->size() * s.width);
            std::size_t off = 0;
            for (const auto& item : *items) {
                if (!is_object(item)) return mismatch(item, "an object for namedarray " + nt->qualified_name);
                if (auto r = namedarray_item_from(item, flat, off, s); !r) return r.take_error();
            }
            return Value(NamedArray{nt->qualified_name, std::move(flat), dims});
        }
        default:
            return fail(MessageErrorType::DataTypeError, "no value of type " + nt->qualified_name);
    }
}

Result<void> Converter::namedarray_item_from(const val& obj, NumericArray& flat, std::size_t& off,
                                             const NamedArrayShape& shape) {
    auto put = [&](const val& x) -> Result<void> {
        auto one = scalar_from_js(x, shape.element_type);
        if (!one) return one.take_error();
        dispatch_numeric(shape.element_type, [&](auto tag) {
            using T = typename decltype(tag)::type;
            flat.mutable_span<T>()[off] = one->template at<T>(0);
        });
        ++off;
        return {};
    };
    for (const auto& m : shape.members) {
        std::string name(m.name);
        val x = obj[name];
        if (!m.array) {
            auto r = m.nested ? namedarray_item_from(x, flat, off, *m.nested) : put(x);
            if (!r) return fail(r.error().type, "field " + name + ": " + r.error().message);
            continue;
        }
        bool arraylike = val::global("Array").call<bool>("isArray", x) || is_typed_array(x);
        if (!arraylike || x["length"].as<std::size_t>() != m.count)
            return fail(MessageErrorType::DataTypeError, "field " + name + ": expected " + std::to_string(m.count) + " items");
        for (std::size_t i = 0; i < m.count; ++i) {
            auto r = m.nested ? namedarray_item_from(x[i], flat, off, *m.nested) : put(x[i]);
            if (!r) return fail(r.error().type, "field " + name + ": " + r.error().message);
        }
    }
    return {};
}

}  // namespace

Result<val> to_js(const Value& value, const TypeDefinition& type, const robdef::TypeLookup& lookup,
                  std::string_view context_service) {
    Converter c(lookup);
    return c.to(value, type, context_service);
}

Result<Value> from_js(const val& v, const TypeDefinition& type, const robdef::TypeLookup& lookup,
                      std::string_view context_service) {
    Converter c(lookup);
    return c.from(v, type, context_service);
}

}  // namespace rr::wasm
