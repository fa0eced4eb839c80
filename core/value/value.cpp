#include "core/value/value.hpp"

namespace rr {

Value::Value(const Value&) = default;
Value::Value(Value&&) noexcept = default;
Value& Value::operator=(const Value&) = default;
Value& Value::operator=(Value&&) noexcept = default;
Value::~Value() = default;

std::string_view value_kind_name(ValueKind kind) noexcept {
    switch (kind) {
        case ValueKind::null: return "null";
        case ValueKind::numeric: return "numeric array";
        case ValueKind::string: return "string";
        case ValueKind::multidim: return "multidimarray";
        case ValueKind::structure: return "struct";
        case ValueKind::pod: return "pod";
        case ValueKind::namedarray: return "namedarray";
        case ValueKind::map_int32: return "int32 map";
        case ValueKind::map_string: return "string map";
        case ValueKind::list: return "list";
        case ValueKind::enumeration: return "enum";
    }
    return "?";
}

// --- Structure -------------------------------------------------------------------------------------

const Value* Structure::find(std::string_view name) const noexcept {
    for (const auto& f : fields)
        if (f.name == name) return &f.value;
    return nullptr;
}

Value* Structure::find(std::string_view name) noexcept {
    return const_cast<Value*>(std::as_const(*this).find(name));
}

Structure& Structure::set(std::string name, Value value) {
    if (Value* v = find(name))
        *v = std::move(value);
    else
        fields.push_back(Field{std::move(name), std::move(value)});
    return *this;
}

bool operator==(const Structure& a, const Structure& b) {
    return a.type_name == b.type_name && a.fields == b.fields;
}

// --- PodArray --------------------------------------------------------------------------------------

Result<void> PodArray::push_back(std::vector<Value> item) {
    if (item.size() != field_names.size())
        return fail(MessageErrorType::DataTypeError, "pod item has " + std::to_string(item.size()) +
                                                         " values, expected " +
                                                         std::to_string(field_names.size()));
    values.reserve(values.size() + item.size());
    for (auto& v : item) values.push_back(std::move(v));
    ++count;
    return {};
}

std::ptrdiff_t PodArray::field_index(std::string_view name) const noexcept {
    for (std::size_t j = 0; j < field_names.size(); ++j)
        if (field_names[j] == name) return static_cast<std::ptrdiff_t>(j);
    return -1;
}

const Value* PodArray::field(std::size_t i, std::string_view name) const noexcept {
    auto j = field_index(name);
    if (j < 0 || i >= count) return nullptr;
    std::size_t k = i * field_names.size() + static_cast<std::size_t>(j);
    return k < values.size() ? &values[k] : nullptr;
}

Value* PodArray::field(std::size_t i, std::string_view name) noexcept {
    return const_cast<Value*>(std::as_const(*this).field(i, name));
}

bool operator==(const PodArray& a, const PodArray& b) {
    return a.type_name == b.type_name && a.field_names == b.field_names && a.values == b.values &&
           a.count == b.count && a.dims == b.dims;
}

// --- containers ------------------------------------------------------------------------------------

const Value* MapInt32::find(std::int32_t key) const noexcept {
    for (const auto& [k, v] : entries)
        if (k == key) return &v;
    return nullptr;
}

const Value* MapString::find(std::string_view key) const noexcept {
    for (const auto& [k, v] : entries)
        if (k == key) return &v;
    return nullptr;
}

bool operator==(const MapInt32& a, const MapInt32& b) { return a.entries == b.entries; }
bool operator==(const MapString& a, const MapString& b) { return a.entries == b.entries; }
bool operator==(const List& a, const List& b) { return a.items == b.items; }

// --- Value -----------------------------------------------------------------------------------------

const Value* Value::field(std::string_view name) const noexcept {
    if (auto* s = get_if<Structure>()) return s->find(name);
    if (auto* p = get_if<PodArray>()) return p->field(0, name);
    return nullptr;
}

Value* Value::field(std::string_view name) noexcept {
    return const_cast<Value*>(std::as_const(*this).field(name));
}

const Value* Value::at(std::size_t i) const noexcept {
    if (auto* l = get_if<List>(); l && i < l->items.size()) return &l->items[i];
    return nullptr;
}

bool operator==(const Value& a, const Value& b) { return a.v_ == b.v_; }

namespace detail {

Result<void> scalar_check(const Value& v, const NumericArray*& out) {
    out = v.get_if<NumericArray>();
    if (!out) return mismatch_error(v, "numeric scalar");
    if (out->size() != 1)
        return fail(MessageErrorType::DataTypeError,
                    "expected a numeric scalar, got an array of " + std::to_string(out->size()) + " items");
    return {};
}

Unexpected out_of_range_error(std::string_view target) {
    return fail(MessageErrorType::OutOfRange, "value does not fit in " + std::string(target));
}

Unexpected mismatch_error(const Value& v, std::string_view target) {
    std::string got(value_kind_name(v.kind()));
    if (auto* a = v.get_if<NumericArray>()) got = std::string(data_type_keyword(a->type())) + " " + got;
    return fail(MessageErrorType::DataTypeMismatch, "expected " + std::string(target) + ", got " + got);
}

}  // namespace detail

}  // namespace rr
