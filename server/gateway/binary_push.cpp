#include "server/gateway/binary_push.hpp"

#include <array>
#include <optional>
#include <cstring>

#include "core/json/json_numbers.hpp"
#include "core/json/value_json.hpp"
#include "base/message/data_types.hpp"
#include "core/value/numeric_array.hpp"

namespace rr::server::gateway {

namespace {

constexpr std::size_t kHeaderBytes = 8;

void put_u32(std::string& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

std::optional<DataTypes> array_type(std::string_view keyword) {
    static constexpr std::array kTypes{DataTypes::double_t, DataTypes::single_t, DataTypes::int8_t,   DataTypes::uint8_t,
                                       DataTypes::int16_t,  DataTypes::uint16_t, DataTypes::int32_t,  DataTypes::uint32_t,
                                       DataTypes::int64_t,  DataTypes::uint64_t, DataTypes::cdouble_t, DataTypes::csingle_t};
    for (auto t : kTypes)
        if (data_type_keyword(t) == keyword) return t;
    return std::nullopt;
}

Unexpected bad(std::string_view what) {
    return fail(MessageErrorType::ProtocolError, "binary push: " + std::string(what));
}

// Replaces the references in `j` by the arrays' numbers.
Result<void> resolve(nlohmann::json& j, std::string_view arrays, std::size_t depth) {
    if (depth > 64) return bad("nested too deeply");
    if (j.is_object() && j.contains("$binary")) {
        const auto& type = j["type"];
        const auto& length = j["length"];
        const auto& offset = j["offset"];
        if (!type.is_string() || !length.is_number_unsigned() || !offset.is_number_unsigned())
            return bad("a reference needs type, length and offset");
        auto t = array_type(type.get<std::string>());
        if (!t) return bad("unknown array type \"" + type.get<std::string>() + "\"");
        const std::uint64_t n = length.get<std::uint64_t>(), at = offset.get<std::uint64_t>();
        const std::size_t item = data_type_size(*t);
        if (at % 8 != 0 || n > arrays.size() / item || at > arrays.size() - n * item)
            return bad("a reference outside the message");
        NumericArray a = NumericArray::zeros(*t, n);
        dispatch_numeric(*t, [&](auto tag) {
            using T = typename decltype(tag)::type;
            if (n) std::memcpy(static_cast<void*>(a.mutable_span<T>().data()), arrays.data() + at, n * item);
        });
        j = json_numbers::array_to_json(a);
        return {};
    }
    if (j.is_structured())
        for (auto& item : j)
            if (auto r = resolve(item, arrays, depth + 1); !r) return r;
    return {};
}

}  // namespace

std::string binary_push_head(std::string_view json_text) {
    std::string out;
    out.reserve(BinaryArrays::padded(kHeaderBytes + json_text.size()));
    out.append(kBinaryPushMagic);
    put_u32(out, static_cast<std::uint32_t>(json_text.size()));
    out.append(json_text);
    out.resize(BinaryArrays::padded(out.size()), '\0');
    return out;
}

std::string binary_push_arrays(const std::vector<SharedBytes>& blobs) {
    std::size_t total = 0;
    for (const auto& b : blobs) total += BinaryArrays::padded(b.size());
    std::string out;
    out.reserve(total);
    for (const auto& b : blobs) {
        out.append(reinterpret_cast<const char*>(b.data()), b.size());
        out.resize(BinaryArrays::padded(out.size()), '\0');
    }
    return out;
}

std::string binary_push_message(std::string_view json_text, const std::vector<SharedBytes>& blobs) {
    std::string out = binary_push_head(json_text);
    out.append(binary_push_arrays(blobs));
    return out;
}

Result<BinaryPushParts> split_binary_push(std::string_view message) {
    if (message.size() < kHeaderBytes || message.substr(0, 4) != kBinaryPushMagic) return bad("no RRJB header");
    std::uint32_t json_bytes = 0;
    for (int i = 0; i < 4; ++i) json_bytes |= std::uint32_t(static_cast<unsigned char>(message[4 + i])) << (8 * i);
    if (json_bytes > message.size() - kHeaderBytes) return bad("the JSON text runs past the message");
    const std::size_t base = BinaryArrays::padded(kHeaderBytes + json_bytes);
    if (base > message.size()) return bad("the arrays start past the message");
    return BinaryPushParts{message.substr(kHeaderBytes, json_bytes), message.substr(base)};
}

Result<nlohmann::json> decode_binary_push(std::string_view message) {
    auto parts = split_binary_push(message);
    if (!parts) return parts.take_error();
    auto j = nlohmann::json::parse(parts->json_text, nullptr, false);
    if (j.is_discarded()) return bad("the JSON text does not parse");
    if (auto r = resolve(j, parts->arrays, 0); !r) return r.take_error();
    return j;
}

}  // namespace rr::server::gateway
