// RR values <-> JavaScript values (js_values.hpp).
#include "wasm-client/src/js_values.hpp"

#include <charconv>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/json/namedarray_shape.hpp"
#include "core/value/element_layout.hpp"
#include "core/value/named_type.hpp"
#include "core/value/var_type.hpp"

namespace rr::wasm {

using emscripten::val;
using robdef::ArrayKind;
using robdef::ContainerKind;
using robdef::NamedTypeKind;
using robdef::TypeDefinition;

namespace {

std::string js_type(const val& v) {
    if (v.isNull()) return "null";
    if (val::global("Array").call<bool>("isArray", v)) return "array";
    return v.typeOf().as<std::string>();
}

Unexpected mismatch(const val& v, std::string_view expected) {
    auto t = js_type(v);
    auto code = (t == "null" || t == "undefined") ? MessageErrorType::NullValue : MessageErrorType::DataTypeMismatch;
    return fail(code, "expected " + std::string(expected) + ", got " + t);
}

const char* typed_array_name(DataTypes t) {
    switch (t) {
        case DataTypes::double_t: case DataTypes::cdouble_t: return "Float64Array";
        case DataTypes::single_t: case DataTypes::csingle_t: return "Float32Array";
        case DataTypes::int8_t: return "Int8Array";
        case DataTypes::uint8_t: case DataTypes::bool_t: return "Uint8Array";
        case DataTypes::int16_t: return "Int16Array";
        case DataTypes::uint16_t: return "Uint16Array";
        case DataTypes::int32_t: return "Int32Array";
        case DataTypes::uint32_t: return "Uint32Array";
        case DataTypes::int64_t: return "BigInt64Array";
        case DataTypes::uint64_t: return "BigUint64Array";
        default: return "Uint8Array";
    }
}

bool is_complex_type(DataTypes t) { return t == DataTypes::cdouble_t || t == DataTypes::csingle_t; }

bool is_typed_array(const val& v) {
    return v.typeOf().as<std::string>() == "object" && !v.isNull() &&
           val::global("ArrayBuffer").call<bool>("isView", v) && !v.instanceof(val::global("DataView"));
}

/// A copy of the array's bytes as a typed array of its type (bool → Uint8Array, complex interleaved).
val typed_array_copy(const NumericArray& a) {
    SharedBytes bytes = a.to_bytes();
    val heap(emscripten::typed_memory_view(bytes.size(), reinterpret_cast<const std::uint8_t*>(bytes.data())));
    val copy = heap.call<val>("slice");  // out of the wasm heap: stays valid when memory grows
    return val::global(typed_array_name(a.type())).new_(copy["buffer"]);
}

template <class T>
val scalar_to_js(T x) {
    if constexpr (std::is_same_v<T, bool>) {
        return val(x);
    } else if constexpr (detail::is_complex_v<T>) {
        val o = val::object();
        o.set("real", static_cast<double>(x.real()));
        o.set("imag", static_cast<double>(x.imag()));
        return o;
    } else if constexpr (std::is_same_v<T, std::int64_t> || std::is_same_v<T, std::uint64_t>) {
        return val::global("BigInt")(val(std::to_string(x)));
    } else {
        return val(static_cast<double>(x));
    }
}

val numeric_array_to_js(const NumericArray& a) {
    if (a.type() == DataTypes::bool_t || is_complex_type(a.type())) {
        val arr = val::array();
        dispatch_numeric(a.type(), [&](auto tag) {
            using T = typename decltype(tag)::type;
            auto view = a.view<T>();
            for (std::size_t i = 0; i < view.size(); ++i) arr.set(i, scalar_to_js<T>(view[i]));
        });
        return arr;
    }
    return typed_array_copy(a);
}

val dims_to_js(const std::vector<std::uint32_t>& dims) {
    val d = val::array();
    for (std::size_t i = 0; i < dims.size(); ++i) d.set(i, dims[i]);
    return d;
}

/// An integer JS value (number or BigInt) as T, range-checked.
template <class T>
Result<T> integer_from_js(const val& v, std::string_view type_name) {
    auto t = v.typeOf().as<std::string>();
    if (t == "bigint") {
        auto text = v.call<std::string>("toString");
        T out{};
        auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
        if (ec != std::errc() || p != text.data() + text.size())
            return fail(MessageErrorType::OutOfRange, text + " does not fit " + std::string(type_name));
        return out;
    }
    if (t != "number") return mismatch(v, "an integer for " + std::string(type_name));
    double d = v.as<double>();
    if (!std::isfinite(d) || std::trunc(d) != d)
        return fail(MessageErrorType::OutOfRange, "not an integer for " + std::string(type_name));
    if (std::fabs(d) > 9007199254740992.0 && sizeof(T) == 8)
        return fail(MessageErrorType::OutOfRange, "number beyond 2^53 for " + std::string(type_name) + ": use a BigInt");
    if (d < static_cast<double>(std::numeric_limits<T>::min()) || d > static_cast<double>(std::numeric_limits<T>::max()))
        return fail(MessageErrorType::OutOfRange, "number does not fit " + std::string(type_name));
    return static_cast<T>(d);
}

template <class T>
Result<T> item_from_js(const val& v) {
    constexpr auto name = data_type_keyword(numeric_type_v<T>);
    if constexpr (std::is_same_v<T, bool>) {
        if (v.typeOf().as<std::string>() != "boolean") return mismatch(v, "a boolean");
        return v.as<bool>();
    } else if constexpr (detail::is_complex_v<T>) {
        if (v.typeOf().as<std::string>() != "object" || v.isNull() || v["real"].typeOf().as<std::string>() != "number" ||
            v["imag"].typeOf().as<std::string>() != "number")
            return mismatch(v, "{real, imag} for " + std::string(name));
        using R = typename T::value_type;
        return T(static_cast<R>(v["real"].as<double>()), static_cast<R>(v["imag"].as<double>()));
    } else if constexpr (std::is_floating_point_v<T>) {
        auto t = v.typeOf().as<std::string>();
        if (t == "bigint") return static_cast<T>(val::global("Number")(v).as<double>());
        if (t != "number") return mismatch(v, "a number for " + std::string(name));
        return static_cast<T>(v.as<double>());
    } else {
        return integer_from_js<T>(v, name);
    }
}

Result<NumericArray> scalar_from_js(const val& v, DataTypes type) {
    return dispatch_numeric(type, [&](auto tag) -> Result<NumericArray> {
        using T = typename decltype(tag)::type;
        auto x = item_from_js<T>(v);
        if (!x) return x.take_error();
        return NumericArray::scalar<T>(*x);
    });
}

/// A typed array of exactly this type (complex: interleaved) is copied as bytes; anything array-like
/// item by item.
Result<NumericArray> array_from_js(const val& v, DataTypes type) {
    if (is_typed_array(v) && v.instanceof(val::global(typed_array_name(type))) &&
        (type != DataTypes::bool_t)) {
        std::size_t nbytes = v["byteLength"].as<std::size_t>();
        std::size_t item = data_type_size(type);
        if (nbytes % item != 0) return fail(MessageErrorType::DataTypeError, "typed array length does not fit complex items");
        NumericArray a = NumericArray::zeros(type, nbytes / item);
        if (nbytes == 0) return a;
        std::byte* dst = dispatch_numeric(type, [&](auto tag) {
            using T = typename decltype(tag)::type;
            return reinterpret_cast<std::byte*>(a.mutable_span<T>().data());
        });
        val src = val::global("Uint8Array").new_(v["buffer"], v["byteOffset"], v["byteLength"]);
        val(emscripten::typed_memory_view(nbytes, reinterpret_cast<std::uint8_t*>(dst))).call<void>("set", src);
        return a;
    }
    bool arraylike = val::global("Array").call<bool>("isArray", v) || is_typed_array(v);
    if (!arraylike) return mismatch(v, std::string("an array of ") + std::string(data_type_keyword(type)));
    std::size_t n = v["length"].as<std::size_t>();
    return dispatch_numeric(type, [&](auto tag) -> Result<NumericArray> {
        using T = typename decltype(tag)::type;
        NumericArray a = NumericArray::zeros(type, n);
        if (n == 0) return a;
        auto out = a.mutable_span<T>();
        for (std::size_t i = 0; i < n; ++i) {
            val item = v[i];
            if constexpr (std::is_same_v<T, bool>) {
                if (item.typeOf().as<std::string>() == "number") {  // Uint8Array of 0/1
                    out[i] = item.as<double>() != 0;
                    continue;
                }
            }
            auto x = item_from_js<T>(item);
            if (!x) return x.take_error();
            out[i] = *x;
        }
        return a;
    });
}

Result<std::vector<std::uint32_t>> dims_from_js(const val& v) {
    if (!val::global("Array").call<bool>("isArray", v) && !is_typed_array(v)) return mismatch(v, "dims: an array");
    std::vector<std::uint32_t> dims;
    std::size_t n = v["length"].as<std::size_t>();
    for (std::size_t i = 0; i < n; ++i) {
        auto d = integer_from_js<std::uint32_t>(v[i], "uint32");
        if (!d) return d.take_error();
        dims.push_back(*d);
    }
    return dims;
}

bool is_object(const val& v) {
    return !v.isNull() && v.typeOf().as<std::string>() == "object" && !val::global("Array").call<bool>("isArray", v);
}

bool is_nullish(const val& v) { return v.isNull() || v.isUndefined(); }

class Converter {
public:
    Converter(const robdef::TypeLookup& lookup) : lookup_(lookup) {}

    Result<val> to(const Value& v, const TypeDefinition& t, std::string_view ctx, int depth = 0);
    Result<Value> from(const val& v, const TypeDefinition& t, std::string_view ctx, int depth = 0);

private:
    static constexpr int kMaxDepth = 64;

    Result<val> named_to(const Value& v, const TypeDefinition& t, std::string_view ctx, int depth);
    Result<val> namedarray_item_to(const val& flat, std::size_t& off, const NamedArrayShape& shape);
    Result<Value> named_from(const val& v, const TypeDefinition& t, std::string_view ctx, int depth);
    Result<void> namedarray_item_from(const val& obj, NumericArray& flat, std::size_t& off, const NamedArrayShape& shape);
    /// The fields of a struct / pod, in definition order.
    static std::vector<const robdef::MemberDefinition*> struct_fields(const NamedType& nt);

    const robdef::TypeLookup& lookup_;
    NamedArrayShapeCache shapes_;
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
        return dispatch_numeric(a->type(), [&](auto tag) -> val {
            using T = typename decltype(tag)::type;
            return scalar_to_js<T>(a->at<T>(0));
        });
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
            val items = val::array();
            std::size_t off = 0;
            for (std::size_t i = 0; i < count; ++i) {
                auto o = namedarray_item_to(flat, off, s);
                if (!o) return o.take_error();
                items.set(i, *o);
            }
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

/// Reads one namedarray item from the typed array `flat` (complex types interleaved) at element `off`.
Result<val> Converter::namedarray_item_to(const val& flat, std::size_t& off, const NamedArrayShape& shape) {
    bool complex = is_complex_type(shape.element_type);
    auto leaf = [&]() -> val {
        if (complex) {
            val o = val::object();
            o.set("real", flat[2 * off]);
            o.set("imag", flat[2 * off + 1]);
            ++off;
            return o;
        }
        return flat[off++];
    };
    val o = val::object();
    for (const auto& m : shape.members) {
        std::string name(m.name);
        if (m.nested) {
            if (!m.array) {
                auto x = namedarray_item_to(flat, off, *m.nested);
                if (!x) return x.take_error();
                o.set(name, *x);
                continue;
            }
            val arr = val::array();
            for (std::size_t i = 0; i < m.count; ++i) {
                auto x = namedarray_item_to(flat, off, *m.nested);
                if (!x) return x.take_error();
                arr.set(i, *x);
            }
            o.set(name, arr);
        } else if (!m.array) {
            o.set(name, leaf());
        } else if (complex) {
            val arr = val::array();
            for (std::size_t i = 0; i < m.count; ++i) arr.set(i, leaf());
            o.set(name, arr);
        } else {
            o.set(name, flat.call<val>("slice", off, off + m.count));
            off += m.count;
        }
    }
    return o;
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
                auto k = integer_from_js<std::int32_t>(key, "int32 map key");
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
        if (is_typed_array(v)) {
            for (DataTypes dt : {DataTypes::double_t, DataTypes::single_t, DataTypes::int8_t, DataTypes::uint8_t,
                                 DataTypes::int16_t, DataTypes::uint16_t, DataTypes::int32_t, DataTypes::uint32_t,
                                 DataTypes::int64_t, DataTypes::uint64_t})
                if (v.instanceof(val::global(typed_array_name(dt)))) {
                    auto a = array_from_js(v, dt);
                    if (!a) return a.take_error();
                    return Value(std::move(*a));
                }
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
            auto x = integer_from_js<std::int32_t>(v, nt->qualified_name);
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
