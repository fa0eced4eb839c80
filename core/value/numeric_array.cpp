#include "core/value/numeric_array.hpp"

namespace rr {

namespace {

// Typed heap storage for `count` items of T, zero-filled. (std::make_shared<T[]> would save the second
// allocation, but libc++ 14 — Emscripten's — does not have it.)
template <class T>
std::pair<std::shared_ptr<void>, void*> allocate_typed(std::size_t count) {
    std::shared_ptr<T[]> p(new T[count]());
    void* data = p.get();
    return {std::shared_ptr<void>(std::move(p), data), data};
}

}  // namespace

NumericArray::NumericArray(DataTypes type) : type_(type) {
    if (!is_numeric(type)) std::abort();
}

NumericArray NumericArray::zeros(DataTypes type, std::size_t count) {
    NumericArray a(type);
    a.count_ = count;
    if (count <= 1) {
        std::memset(std::get<Inline>(a.store_).buf, 0, sizeof(Inline::buf));  // 0 is every type's zero
        return a;
    }
    auto [keep, data] = dispatch_numeric(type, [&](auto tag) {
        return allocate_typed<typename decltype(tag)::type>(count);
    });
    a.store_ = Owned{std::move(keep), data};
    return a;
}

Result<NumericArray> NumericArray::wrap(DataTypes type, SharedBytes bytes) {
    if (!is_numeric(type))
        return fail(MessageErrorType::DataTypeError,
                    "element type " + std::to_string(static_cast<int>(type)) + " is not a numeric array");
    std::size_t item = data_type_size(type);
    if (bytes.size() % item != 0)
        return fail(MessageErrorType::DataTypeError, "numeric array byte count " + std::to_string(bytes.size()) +
                                                         " is not a multiple of the item size " +
                                                         std::to_string(item));
    NumericArray a(type);
    a.count_ = bytes.size() / item;
    if (a.count_ <= 1) {
        // A scalar is cheaper to copy than to keep the whole receive buffer alive.
        if (a.count_ == 1) std::memcpy(std::get<Inline>(a.store_).buf, bytes.data(), item);
        return a;
    }
    a.store_ = std::move(bytes);
    return a;
}

const std::byte* NumericArray::read_ptr() const noexcept {
    switch (store_.index()) {
        case 0: return std::get<Inline>(store_).buf;
        case 1: return static_cast<const std::byte*>(std::get<Owned>(store_).data);
        default: return std::get<SharedBytes>(store_).data();
    }
}

void NumericArray::make_unique() {
    if (std::holds_alternative<Inline>(store_)) return;
    if (auto* o = std::get_if<Owned>(&store_); o && o->keep.use_count() == 1) return;
    // Copy the items (view or shared buffer) into fresh typed storage. bool is normalised to 0/1.
    const std::byte* src = read_ptr();
    NumericArray fresh = zeros(type_, count_);
    dispatch_numeric(type_, [&](auto tag) {
        using T = typename decltype(tag)::type;
        T* dst = fresh.typed_ptr<T>();
        if constexpr (std::is_same_v<T, bool>) {
            for (std::size_t i = 0; i < count_; ++i) dst[i] = detail::load_item<bool>(src + i);
        } else if (count_ != 0) {
            std::memcpy(static_cast<void*>(dst), src, count_ * sizeof(T));
        }
    });
    store_ = std::move(fresh.store_);
}

void NumericArray::make_owned() {
    if (is_view()) make_unique();
}

SharedBytes NumericArray::to_bytes() const {
    std::size_t n = count_ * item_size();
    switch (store_.index()) {
        case 0: return SharedBytes::copy_of(std::get<Inline>(store_).buf, n);
        case 1: {
            const auto& o = std::get<Owned>(store_);
            return SharedBytes(o.keep, std::span<const std::byte>(static_cast<const std::byte*>(o.data), n));
        }
        default: return std::get<SharedBytes>(store_);
    }
}

bool operator==(const NumericArray& a, const NumericArray& b) noexcept {
    if (a.type_ != b.type_ || a.count_ != b.count_) return false;
    if (a.count_ == 0) return true;
    if (a.type_ == DataTypes::bool_t) {
        auto va = a.view<bool>(), vb = b.view<bool>();
        for (std::size_t i = 0; i < va.size(); ++i)
            if (va[i] != vb[i]) return false;
        return true;
    }
    return std::memcmp(a.read_ptr(), b.read_ptr(), a.count_ * a.item_size()) == 0;
}

}  // namespace rr
