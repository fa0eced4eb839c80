// JS numbers, typed arrays and shapes <-> NumericArray (js_numbers.hpp).
#include "wasm-client/src/js_numbers.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <string>

namespace rr::wasm {

using emscripten::val;

namespace {

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

}  // namespace

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

std::optional<DataTypes> typed_array_type(const val& v) {
    if (!is_typed_array(v)) return std::nullopt;
    for (DataTypes dt : {DataTypes::double_t, DataTypes::single_t, DataTypes::int8_t, DataTypes::uint8_t,
                         DataTypes::int16_t, DataTypes::uint16_t, DataTypes::int32_t, DataTypes::uint32_t,
                         DataTypes::int64_t, DataTypes::uint64_t})
        if (v.instanceof(val::global(typed_array_name(dt)))) return dt;
    return std::nullopt;
}

val numeric_scalar_to_js(const NumericArray& a) {
    return dispatch_numeric(a.type(), [&](auto tag) -> val {
        using T = typename decltype(tag)::type;
        return scalar_to_js<T>(a.at<T>(0));
    });
}

Result<std::int32_t> int32_from_js(const val& v, std::string_view type_name) {
    return integer_from_js<std::int32_t>(v, type_name);
}

}  // namespace rr::wasm
