// rr::Value: a self-describing Robot Raconteur value (robdef.md §6, wire.md §3.2, STD value_types.md).
//
// One Value holds one of:
//   Null            void / null (wire element type 0)
//   NumericArray    numeric scalar or 1-D array (scalar = length 1; the robdef type decides)
//   std::string     `string` (UTF-8)
//   MultiDimArray   numeric multi-dim array: dims + column-major flat array
//   Structure       struct: qualified type name + ordered named fields
//   PodArray        pod scalar / array / multi-dim: qualified type name + per-item fields
//   NamedArray      namedarray scalar / array / multi-dim: qualified type name + flat numeric array
//   MapInt32        T{int32}, insertion order kept
//   MapString       T{string}, insertion order kept
//   List            T{list}
//   Enum            enum value: int32 + qualified enum type name (empty when unknown)
// A `varvalue` is just a Value; var_type_string() (var_type.hpp) names its RR type as Python does.
//
// Copying a Value is a deep copy of the tree, except numeric data, which is shared copy-on-write.
// Moving is cheap. Values are not thread-safe for concurrent mutation (like std containers).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "base/error/rr_error.hpp"
#include "core/value/numeric_array.hpp"

namespace rr {

class Value;

/// void / null.
struct Null {
    friend bool operator==(const Null&, const Null&) = default;
};

/// Numeric multi-dim array (wire element 117). `array.size()` == product of `dims`; items are in
/// column-major (Fortran) order: index (i0, i1, …) is at i0 + d0*(i1 + d1*(i2 + …)).
struct MultiDimArray {
    std::vector<std::uint32_t> dims;
    NumericArray array;

    friend bool operator==(const MultiDimArray&, const MultiDimArray&) = default;
};

/// One named field of a struct (or of one pod item).
struct Field;

/// A struct value (wire element 101). `type_name` is fully qualified (`svc.Struct`). Fields are kept in
/// the order given; packing writes them in definition order and looks them up by name.
struct Structure {
    std::string type_name;
    std::vector<Field> fields;

    /// Field value by name, or nullptr.
    const Value* find(std::string_view name) const noexcept;
    Value* find(std::string_view name) noexcept;
    /// Sets (replacing) or appends a field; returns *this for chaining.
    Structure& set(std::string name, Value value);

    friend bool operator==(const Structure&, const Structure&);
};

/// Pods (wire elements 110 / 111): `count` items of pod type `type_name`, each with one value per name in
/// `field_names`. Values are stored flat, item-major: field j of item i is `values[i * field_names.size()
/// + j]`. Scalar pods have count 1 (the robdef type decides scalar-ness). `dims` is non-empty only for a
/// multi-dim pod array (column-major, product == count).
/// Field values: NumericArray for numeric scalars/arrays, MultiDimArray for fixed multi-dim numeric
/// fields, PodArray / NamedArray for nested pod / namedarray fields (with `dims` for multi-dim fields).
struct PodArray {
    std::string type_name;
    std::vector<std::string> field_names;
    std::vector<Value> values;
    std::size_t count = 0;
    std::vector<std::uint32_t> dims;

    PodArray();
    /// No items yet: add them with push_back.
    PodArray(std::string type, std::vector<std::string> names);

    std::size_t size() const noexcept { return count; }
    /// Appends one item. Errors: DataTypeError when item.size() != field_names.size().
    Result<void> push_back(std::vector<Value> item);
    /// Value of field `name` of item `i`, or nullptr (unknown name or i >= count).
    const Value* field(std::size_t i, std::string_view name) const noexcept;
    Value* field(std::size_t i, std::string_view name) noexcept;
    /// Index of `name` in field_names, or -1.
    std::ptrdiff_t field_index(std::string_view name) const noexcept;

    friend bool operator==(const PodArray&, const PodArray&);
};

/// Namedarrays (wire elements 115 / 116): items of namedarray type `type_name` stored as one flat numeric
/// array of the namedarray's element type (item i occupies [i*k, (i+1)*k) where k = elements per item,
/// known from the definition). `dims` non-empty only for a multi-dim namedarray array.
struct NamedArray {
    std::string type_name;
    NumericArray array;
    std::vector<std::uint32_t> dims;

    friend bool operator==(const NamedArray&, const NamedArray&) = default;
};

/// T{int32} (wire element 102); insertion order is kept, keys are unique when packed.
struct MapInt32 {
    std::vector<std::pair<std::int32_t, Value>> entries;
    const Value* find(std::int32_t key) const noexcept;
    friend bool operator==(const MapInt32&, const MapInt32&);
};

/// T{string} (wire element 103); insertion order is kept, keys are unique when packed.
struct MapString {
    std::vector<std::pair<std::string, Value>> entries;
    const Value* find(std::string_view key) const noexcept;
    friend bool operator==(const MapString&, const MapString&);
};

/// T{list} (wire element 108).
struct List {
    std::vector<Value> items;
    friend bool operator==(const List&, const List&);
};

/// An enum value. Travels as an int32 scalar (wire.md §3.2); `type_name` is the qualified enum name when
/// known (filled by unpacking with a robdef), else empty.
struct Enum {
    std::string type_name;
    std::int32_t value = 0;
    friend bool operator==(const Enum&, const Enum&) = default;
};

/// Kind of value held, in the order of Value's alternatives.
enum class ValueKind : std::uint8_t {
    null,
    numeric,
    string,
    multidim,
    structure,
    pod,
    namedarray,
    map_int32,
    map_string,
    list,
    enumeration,
};

/// "null", "numeric array", "string", "multidimarray", "struct", "pod", "namedarray", "int32 map",
/// "string map", "list", "enum": for error messages.
std::string_view value_kind_name(ValueKind kind) noexcept;

namespace detail {
/// Heap box with value semantics: keeps rarely used large alternatives out of Value's footprint.
template <class T>
class Box {
public:
    Box(T v) : p_(std::make_unique<T>(std::move(v))) {}
    Box(const Box& o) : p_(std::make_unique<T>(*o.p_)) {}
    Box(Box&&) noexcept = default;
    Box& operator=(const Box& o) {
        if (this != &o) p_ = std::make_unique<T>(*o.p_);
        return *this;
    }
    Box& operator=(Box&&) noexcept = default;
    T& get() noexcept { return *p_; }
    const T& get() const noexcept { return *p_; }
    friend bool operator==(const Box& a, const Box& b) { return *a.p_ == *b.p_; }

private:
    std::unique_ptr<T> p_;
};
}  // namespace detail

class Value {
public:
    Value() noexcept = default;  ///< null
    Value(Null) noexcept {}
    Value(std::nullptr_t) noexcept {}  ///< null (never a string)
    Value(NumericArray a);
    Value(std::string s);
    Value(const char* s);  ///< a string; `s` must not be null
    Value(MultiDimArray m);
    Value(Structure s);
    Value(PodArray p);
    Value(NamedArray n);
    Value(MapInt32 m);
    Value(MapString m);
    Value(List l);
    Value(Enum e);

    Value(const Value&);
    Value(Value&&) noexcept;
    Value& operator=(const Value&);
    Value& operator=(Value&&) noexcept;
    ~Value();

    /// A numeric scalar: `Value::scalar<double>(1.5)`, `Value::scalar(std::int32_t{3})`.
    template <Numeric T>
    static Value scalar(T v) {
        return Value(NumericArray::scalar<T>(v));
    }
    /// A numeric array (copied).
    template <Numeric T>
    static Value array(std::initializer_list<T> items) {
        return Value(NumericArray::from<T>(items));
    }
    template <Numeric T>
    static Value array(std::span<const T> items) {
        return Value(NumericArray::from<T>(items));
    }

    ValueKind kind() const noexcept { return static_cast<ValueKind>(v_.index()); }
    bool is_null() const noexcept { return kind() == ValueKind::null; }

    /// Pointer to the alternative A, or nullptr: `v.get_if<Structure>()`.
    template <class A>
    const A* get_if() const noexcept {
        if constexpr (is_boxed<A>) {
            auto* b = std::get_if<detail::Box<A>>(&v_);
            return b ? &b->get() : nullptr;
        } else {
            return std::get_if<A>(&v_);
        }
    }
    template <class A>
    A* get_if() noexcept {
        return const_cast<A*>(std::as_const(*this).get_if<A>());
    }
    template <class A>
    bool is() const noexcept {
        return get_if<A>() != nullptr;
    }

    /// Scalar conversion. Numeric T: the value must be a NumericArray of exactly one item (or an Enum);
    /// integers convert to any integer type whose range holds the value, integers and reals to float/double,
    /// reals and complex to complex; bool only from bool. T = std::string: the value must be a string.
    /// Errors: DataTypeMismatch (other kind or no allowed conversion), DataTypeError (not one item),
    /// OutOfRange (integer does not fit T).
    template <class T>
    Result<T> as() const;

    /// Field of a struct (or of a scalar pod: item 0), or nullptr.
    const Value* field(std::string_view name) const noexcept;
    Value* field(std::string_view name) noexcept;
    /// Item `i` of a list, or nullptr.
    const Value* at(std::size_t i) const noexcept;

    friend bool operator==(const Value&, const Value&);

private:
    template <class A>
    static constexpr bool is_boxed = std::is_same_v<A, MultiDimArray> || std::is_same_v<A, Structure> ||
                                     std::is_same_v<A, PodArray> || std::is_same_v<A, NamedArray>;

    std::variant<Null, NumericArray, std::string, detail::Box<MultiDimArray>, detail::Box<Structure>,
                 detail::Box<PodArray>, detail::Box<NamedArray>, MapInt32, MapString, List, Enum>
        v_;
};

struct Field {
    std::string name;
    Value value;
    friend bool operator==(const Field&, const Field&) = default;
};

// Defined here, where Field and Value are complete (containers of them need complete types).
inline Value::Value(NumericArray a) : v_(std::move(a)) {}
inline Value::Value(std::string s) : v_(std::move(s)) {}
inline Value::Value(const char* s) : v_(std::string(s)) {}
inline Value::Value(MultiDimArray m) : v_(detail::Box<MultiDimArray>(std::move(m))) {}
inline Value::Value(Structure s) : v_(detail::Box<Structure>(std::move(s))) {}
inline Value::Value(PodArray p) : v_(detail::Box<PodArray>(std::move(p))) {}
inline Value::Value(NamedArray n) : v_(detail::Box<NamedArray>(std::move(n))) {}
inline Value::Value(MapInt32 m) : v_(std::move(m)) {}
inline Value::Value(MapString m) : v_(std::move(m)) {}
inline Value::Value(List l) : v_(std::move(l)) {}
inline Value::Value(Enum e) : v_(std::move(e)) {}
inline PodArray::PodArray() = default;
inline PodArray::PodArray(std::string type, std::vector<std::string> names)
    : type_name(std::move(type)), field_names(std::move(names)) {}

// --- Value::as -------------------------------------------------------------------------------------

namespace detail {
/// Sets `out` to the NumericArray of `v`; DataTypeMismatch when not numeric, DataTypeError when not 1 item.
Result<void> scalar_check(const Value& v, const NumericArray*& out);
Unexpected out_of_range_error(std::string_view target);
Unexpected mismatch_error(const Value& v, std::string_view target);
}  // namespace detail

template <class T>
Result<T> Value::as() const {
    if constexpr (std::is_same_v<T, std::string>) {
        if (auto* s = get_if<std::string>()) return *s;
        return detail::mismatch_error(*this, "string");
    } else {
        static_assert(Numeric<T>, "Value::as<T>: T must be an RR numeric type or std::string");
        constexpr DataTypes target = numeric_type_v<T>;
        if (auto* e = get_if<Enum>()) {
            if constexpr (std::is_same_v<T, bool> || detail::is_complex_v<T>) {
                return detail::mismatch_error(*this, data_type_keyword(target));
            } else if constexpr (std::is_floating_point_v<T>) {
                return static_cast<T>(e->value);
            } else {
                if (!std::in_range<T>(e->value)) return detail::out_of_range_error(data_type_keyword(target));
                return static_cast<T>(e->value);
            }
        }
        const NumericArray* a = nullptr;
        if (auto r = detail::scalar_check(*this, a); !r) return r.take_error();
        return dispatch_numeric(a->type(), [&](auto tag) -> Result<T> {
            using S = typename decltype(tag)::type;
            S s = a->at<S>(0);
            if constexpr (std::is_same_v<S, T>) {
                return s;
            } else if constexpr (std::is_same_v<T, bool> || std::is_same_v<S, bool>) {
                return detail::mismatch_error(*this, data_type_keyword(target));
            } else if constexpr (detail::is_complex_v<T>) {
                if constexpr (detail::is_complex_v<S>)
                    return T(static_cast<typename T::value_type>(s.real()),
                             static_cast<typename T::value_type>(s.imag()));
                else
                    return T(static_cast<typename T::value_type>(s), 0);
            } else if constexpr (detail::is_complex_v<S>) {
                return detail::mismatch_error(*this, data_type_keyword(target));
            } else if constexpr (std::is_floating_point_v<T>) {
                return static_cast<T>(s);
            } else if constexpr (std::is_floating_point_v<S>) {
                return detail::mismatch_error(*this, data_type_keyword(target));
            } else {
                if (!std::in_range<T>(s)) return detail::out_of_range_error(data_type_keyword(target));
                return static_cast<T>(s);
            }
        });
    }
}

}  // namespace rr
