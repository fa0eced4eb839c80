// NumericArray: a typed 1-D array of one RR numeric primitive (double … uint64, cdouble, csingle, bool).
//
// Wire form: wire.md §3.2 "Scalars and numeric arrays": one element whose data is the raw little-endian
// array; a scalar is an array of length 1 and only the robdef type decides scalar-ness.
//
// Storage (one of three, chosen automatically):
//   * inline  — 0 or 1 item kept inside the object (no allocation: scalars are cheap);
//   * owned   — one typed heap buffer, shared copy-on-write between copies of the array;
//   * view    — the SharedBytes of a received element, wrapped without copying (zero-copy).
// Reads work on every storage (view<T>(), at<T>()); typed std::spans need typed storage (span<T>()),
// which locally built arrays always have and a view gets from make_owned() (one copy). Received bytes are
// never reinterpreted as T: a view is read item by item with memcpy/bit_cast (alignment- and endian-safe).
//
// Thread safety: like std::shared_ptr — distinct objects may be used from different threads, even when
// they share a buffer; one object must not be mutated while another thread reads it.
#pragma once

#include "base/codec/bit_cast.hpp"
#include <array>
#include <bit>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <memory>
#include <new>
#include <span>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "base/codec/shared_bytes.hpp"
#include "base/error/rr_error.hpp"
#include "base/message/data_types.hpp"

namespace rr {

// Typed storage doubles as the wire form (the object representation of each item is its little-endian
// wire bytes), which is what makes packing zero-copy. Every target we build for (x86-64, AArch64,
// WebAssembly) is little-endian; a big-endian port would add byte swaps in load_item/store_item,
// to_bytes() and make_owned().
static_assert(std::endian::native == std::endian::little, "core/value assumes a little-endian host");

using cdouble = std::complex<double>;  ///< RR `cdouble`: real then imaginary double on the wire
using csingle = std::complex<float>;   ///< RR `csingle`: real then imaginary float on the wire

/// Maps a C++ item type to its DataTypes code (double → double_t, bool → bool_t, …).
template <class T>
struct numeric_type_of;
template <> struct numeric_type_of<double> { static constexpr DataTypes value = DataTypes::double_t; };
template <> struct numeric_type_of<float> { static constexpr DataTypes value = DataTypes::single_t; };
template <> struct numeric_type_of<std::int8_t> { static constexpr DataTypes value = DataTypes::int8_t; };
template <> struct numeric_type_of<std::uint8_t> { static constexpr DataTypes value = DataTypes::uint8_t; };
template <> struct numeric_type_of<std::int16_t> { static constexpr DataTypes value = DataTypes::int16_t; };
template <> struct numeric_type_of<std::uint16_t> { static constexpr DataTypes value = DataTypes::uint16_t; };
template <> struct numeric_type_of<std::int32_t> { static constexpr DataTypes value = DataTypes::int32_t; };
template <> struct numeric_type_of<std::uint32_t> { static constexpr DataTypes value = DataTypes::uint32_t; };
template <> struct numeric_type_of<std::int64_t> { static constexpr DataTypes value = DataTypes::int64_t; };
template <> struct numeric_type_of<std::uint64_t> { static constexpr DataTypes value = DataTypes::uint64_t; };
template <> struct numeric_type_of<cdouble> { static constexpr DataTypes value = DataTypes::cdouble_t; };
template <> struct numeric_type_of<csingle> { static constexpr DataTypes value = DataTypes::csingle_t; };
template <> struct numeric_type_of<bool> { static constexpr DataTypes value = DataTypes::bool_t; };

/// A C++ type that is the item type of an RR numeric array.
template <class T>
concept Numeric = requires { numeric_type_of<T>::value; };

template <Numeric T>
inline constexpr DataTypes numeric_type_v = numeric_type_of<T>::value;

/// Tag passed by dispatch_numeric.
template <class T>
struct type_tag {
    using type = T;
};

/// Calls `f(type_tag<T>{})` with the C++ item type of numeric code `t`. Precondition: is_numeric(t).
template <class F>
decltype(auto) dispatch_numeric(DataTypes t, F&& f) {
    switch (t) {
        case DataTypes::double_t: return f(type_tag<double>{});
        case DataTypes::single_t: return f(type_tag<float>{});
        case DataTypes::int8_t: return f(type_tag<std::int8_t>{});
        case DataTypes::uint8_t: return f(type_tag<std::uint8_t>{});
        case DataTypes::int16_t: return f(type_tag<std::int16_t>{});
        case DataTypes::uint16_t: return f(type_tag<std::uint16_t>{});
        case DataTypes::int32_t: return f(type_tag<std::int32_t>{});
        case DataTypes::uint32_t: return f(type_tag<std::uint32_t>{});
        case DataTypes::int64_t: return f(type_tag<std::int64_t>{});
        case DataTypes::uint64_t: return f(type_tag<std::uint64_t>{});
        case DataTypes::cdouble_t: return f(type_tag<cdouble>{});
        case DataTypes::csingle_t: return f(type_tag<csingle>{});
        case DataTypes::bool_t: return f(type_tag<bool>{});
        default: std::abort();
    }
}

namespace detail {

template <class T>
inline constexpr bool is_complex_v = false;
template <class R>
inline constexpr bool is_complex_v<std::complex<R>> = true;

/// Reads one little-endian item from `p` (any alignment). bool: any non-zero byte is true.
/// (Bytes are copied into a T with memcpy/bit_cast: received bytes are never reinterpreted in place.)
template <Numeric T>
T load_item(const std::byte* p) noexcept {
    if constexpr (std::is_same_v<T, bool>) {
        return *p != std::byte{0};
    } else if constexpr (is_complex_v<T>) {
        using R = typename T::value_type;
        return T(load_item<R>(p), load_item<R>(p + sizeof(R)));
    } else {
        std::array<std::byte, sizeof(T)> b;
        std::memcpy(b.data(), p, sizeof(T));
        return rr::bit_cast<T>(b);
    }
}

/// Writes one item to `p` as little-endian bytes (any alignment).
template <Numeric T>
void store_item(std::byte* p, T v) noexcept {
    if constexpr (std::is_same_v<T, bool>) {
        *p = v ? std::byte{1} : std::byte{0};
    } else if constexpr (is_complex_v<T>) {
        using R = typename T::value_type;
        store_item<R>(p, v.real());
        store_item<R>(p + sizeof(R), v.imag());
    } else {
        auto b = rr::bit_cast<std::array<std::byte, sizeof(T)>>(v);
        std::memcpy(p, b.data(), sizeof(T));
    }
}

}  // namespace detail

/// Read-only, zero-copy, random-access view of `size()` items of T stored little-endian. Items are
/// returned by value (loaded with memcpy), so the bytes need no alignment. Valid while the array it came
/// from is alive and unmodified.
template <Numeric T>
class NumericView {
public:
    class iterator {
    public:
        using value_type = T;
        using difference_type = std::ptrdiff_t;
        using reference = T;
        using iterator_category = std::input_iterator_tag;
        iterator() = default;
        T operator*() const noexcept { return detail::load_item<T>(p_); }
        iterator& operator++() noexcept { p_ += sizeof(T); return *this; }
        iterator operator++(int) noexcept { auto c = *this; ++*this; return c; }
        friend bool operator==(const iterator&, const iterator&) = default;

    private:
        friend class NumericView;
        explicit iterator(const std::byte* p) : p_(p) {}
        const std::byte* p_ = nullptr;
    };

    NumericView() = default;
    NumericView(const std::byte* data, std::size_t count) noexcept : data_(data), count_(count) {}

    std::size_t size() const noexcept { return count_; }
    bool empty() const noexcept { return count_ == 0; }
    /// Item `i`; precondition i < size().
    T operator[](std::size_t i) const noexcept { return detail::load_item<T>(data_ + i * sizeof(T)); }
    iterator begin() const noexcept { return iterator(data_); }
    iterator end() const noexcept { return iterator(data_ + count_ * sizeof(T)); }

private:
    const std::byte* data_ = nullptr;
    std::size_t count_ = 0;
};

class NumericArray {
public:
    /// Empty `double` array.
    NumericArray() noexcept = default;
    /// Empty array of numeric type `type`. Aborts when !is_numeric(type) (programming error).
    explicit NumericArray(DataTypes type);

    /// `count` zero items of `type` in typed storage. Aborts when !is_numeric(type).
    static NumericArray zeros(DataTypes type, std::size_t count);
    /// One item (a robdef scalar).
    template <Numeric T>
    static NumericArray scalar(T v) {
        NumericArray a(numeric_type_v<T>);
        a.count_ = 1;
        ::new (static_cast<void*>(std::get<Inline>(a.store_).buf)) T(v);
        return a;
    }
    /// Copies `items` into typed storage.
    template <Numeric T>
    static NumericArray from(std::span<const T> items) {
        NumericArray a = zeros(numeric_type_v<T>, items.size());
        if (!items.empty()) std::memcpy(static_cast<void*>(a.mutable_span<T>().data()), items.data(), items.size_bytes());
        return a;
    }
    template <Numeric T>
    static NumericArray from(std::initializer_list<T> items) {
        return from(std::span<const T>(items.begin(), items.size()));
    }
    /// Takes over `items` without copying them (not for bool: std::vector<bool> is not contiguous).
    template <Numeric T>
        requires(!std::is_same_v<T, bool>)
    static NumericArray adopt(std::vector<T>&& items) {
        NumericArray a(numeric_type_v<T>);
        a.count_ = items.size();
        auto holder = std::make_shared<std::vector<T>>(std::move(items));
        void* data = holder->data();
        a.store_ = Owned{std::move(holder), data};
        return a;
    }
    /// Wraps the little-endian bytes of a received element without copying.
    /// Errors: DataTypeError when !is_numeric(type) or bytes.size() is not a multiple of the item size.
    static Result<NumericArray> wrap(DataTypes type, SharedBytes bytes);

    DataTypes type() const noexcept { return type_; }
    std::size_t size() const noexcept { return count_; }
    bool empty() const noexcept { return count_ == 0; }
    std::size_t item_size() const noexcept { return data_type_size(type_); }
    /// True when this wraps received bytes (see wrap()).
    bool is_view() const noexcept { return std::holds_alternative<SharedBytes>(store_); }

    /// Zero-copy read access. Aborts when T does not match type().
    template <Numeric T>
    NumericView<T> view() const {
        check_type<T>();
        return NumericView<T>(read_ptr(), count_);
    }
    /// Item `i`; precondition i < size(). Aborts when T does not match type().
    template <Numeric T>
    T at(std::size_t i) const {
        return view<T>()[i];
    }
    /// Typed span over typed storage. Aborts when T does not match type() or is_view() (call
    /// make_owned() first, or use view<T>()).
    template <Numeric T>
    std::span<const T> span() const {
        check_type<T>();
        if (is_view()) std::abort();
        return std::span<const T>(typed_ptr<T>(), count_);
    }
    /// Writable typed span. Copies first when the storage is a view or is shared (copy-on-write).
    /// Aborts when T does not match type().
    template <Numeric T>
    std::span<T> mutable_span() {
        check_type<T>();
        make_unique();
        return std::span<T>(typed_ptr<T>(), count_);
    }
    /// Converts a view into typed storage (one copy); no-op otherwise.
    void make_owned();

    /// The little-endian bytes, for a MessageElement's data. Zero-copy for views and (on little-endian
    /// hosts) for owned storage; inline items are copied (at most 16 bytes).
    SharedBytes to_bytes() const;

    /// Same type, same size and bit-identical items (so NaN == NaN with the same payload, 0.0 != -0.0).
    friend bool operator==(const NumericArray& a, const NumericArray& b) noexcept;

private:
    struct Inline {
        alignas(16) std::byte buf[16];
    };
    struct Owned {
        std::shared_ptr<void> keep;
        void* data = nullptr;
    };

    template <Numeric T>
    void check_type() const {
        if (numeric_type_v<T> != type_) std::abort();
    }
    template <Numeric T>
    T* typed_ptr() const noexcept {
        if (auto* o = std::get_if<Owned>(&store_)) return static_cast<T*>(o->data);
        auto& in = const_cast<Inline&>(std::get<Inline>(store_));
        return std::launder(reinterpret_cast<T*>(in.buf));
    }
    const std::byte* read_ptr() const noexcept;
    void make_unique();

    DataTypes type_ = DataTypes::double_t;
    std::size_t count_ = 0;
    std::variant<Inline, Owned, SharedBytes> store_{Inline{}};
};

}  // namespace rr
