#include "server/record/foxglove_image.hpp"

#include <openssl/evp.h>

#include <cstddef>
#include <span>
#include <vector>

namespace rr::server::record {
namespace {

using nlohmann::json;

constexpr std::uint64_t kNsPerSec = 1000000000ull;
constexpr std::int64_t kDaySeconds = 86400;

// Base64 (RFC 4648, padded) with OpenSSL's encoder; EVP_EncodeBlock writes 4 bytes per 3 and a NUL.
std::string base64(std::span<const std::byte> bytes) {
    std::string out(4 * ((bytes.size() + 2) / 3) + 1, '\0');
    const int n = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(out.data()),
                                  reinterpret_cast<const unsigned char*>(bytes.data()), static_cast<int>(bytes.size()));
    out.resize(n < 0 ? 0 : static_cast<std::size_t>(n));
    return out;
}

// The image's bytes: a {"$binary": i} reference (element_json with BinaryArrays) or a JSON number array.
std::optional<std::span<const std::byte>> image_bytes(const json& data, const BinaryArrays& binary,
                                                      std::vector<std::byte>& storage) {
    if (data.is_object() && data.contains("$binary") && data["$binary"].is_number_integer()) {
        const auto i = data["$binary"].get<std::int64_t>();
        if (i < 0 || static_cast<std::size_t>(i) >= binary.blobs.size()) return std::nullopt;
        return binary.blobs[static_cast<std::size_t>(i)].bytes();
    }
    if (!data.is_array()) return std::nullopt;
    storage.reserve(data.size());
    for (const auto& b : data) {
        if (!b.is_number_integer() || b.get<std::int64_t>() < 0 || b.get<std::int64_t>() > 255) return std::nullopt;
        storage.push_back(static_cast<std::byte>(b.get<std::int64_t>()));
    }
    return std::span<const std::byte>(storage);
}

std::optional<std::string_view> compressed_format(std::span<const std::byte> b) {
    auto at = [&](std::size_t i) { return std::to_integer<unsigned>(b[i]); };
    if (b.size() >= 3 && at(0) == 0xFF && at(1) == 0xD8 && at(2) == 0xFF) return "jpeg";
    if (b.size() >= 8 && at(0) == 0x89 && at(1) == 'P' && at(2) == 'N' && at(3) == 'G') return "png";
    if (b.size() >= 12 && at(0) == 'R' && at(1) == 'I' && at(2) == 'F' && at(3) == 'F' && at(8) == 'W' && at(9) == 'E' &&
        at(10) == 'B' && at(11) == 'P')
        return "webp";
    return std::nullopt;
}

json timestamp(const json& image_info, std::uint64_t log_ns) {
    std::uint64_t ns = log_ns;
    const json* ts = nullptr;
    if (image_info.is_object() && image_info.contains("data_header") && image_info["data_header"].is_object() &&
        image_info["data_header"].contains("ts"))
        ts = &image_info["data_header"]["ts"];
    if (ts && ts->is_object() && (*ts)["seconds"].is_number_integer() && (*ts)["nanoseconds"].is_number_integer()) {
        const auto sec = (*ts)["seconds"].get<std::int64_t>();
        const auto nsec = (*ts)["nanoseconds"].get<std::int64_t>();
        const auto log_sec = static_cast<std::int64_t>(log_ns / kNsPerSec);
        if (sec > 0 && nsec >= 0 && nsec < static_cast<std::int64_t>(kNsPerSec) && sec > log_sec - kDaySeconds &&
            sec < log_sec + kDaySeconds)
            ns = static_cast<std::uint64_t>(sec) * kNsPerSec + static_cast<std::uint64_t>(nsec);
    }
    return json{{"sec", ns / kNsPerSec}, {"nsec", ns % kNsPerSec}};
}

json time_schema() {
    return json{{"type", "object"},
                {"properties", {{"sec", {{"type", "integer"}, {"minimum", 0}}},
                                {"nsec", {{"type", "integer"}, {"minimum", 0}, {"maximum", 999999999}}}}},
                {"required", {"sec", "nsec"}}};
}

}  // namespace

std::optional<FoxgloveImageKind> foxglove_image_kind(const robdef::TypeDefinition& type,
                                                     const robdef::TypeLookup& lookup, std::string_view context) {
    if (type.base != DataTypes::namedtype_t || type.array != robdef::ArrayKind::none ||
        type.container != robdef::ContainerKind::none)
        return std::nullopt;
    auto ref = lookup.find(type.type_name, context);
    if (!ref || !ref.entry || ref.service->name != "com.robotraconteur.image") return std::nullopt;
    if (ref.entry->name == "Image") return FoxgloveImageKind::raw;
    if (ref.entry->name == "CompressedImage") return FoxgloveImageKind::compressed;
    return std::nullopt;
}

std::string_view foxglove_schema_name(FoxgloveImageKind kind) {
    return kind == FoxgloveImageKind::raw ? "foxglove.RawImage" : "foxglove.CompressedImage";
}

nlohmann::json foxglove_image_schema(FoxgloveImageKind kind) {
    json props{{"timestamp", time_schema()},
               {"frame_id", {{"type", "string"}}},
               {"data", {{"type", "string"}, {"contentEncoding", "base64"}}}};
    json required{"timestamp", "frame_id", "data"};
    if (kind == FoxgloveImageKind::raw) {
        for (const char* k : {"width", "height", "step"}) {
            props[k] = json{{"type", "integer"}, {"minimum", 0}};
            required.push_back(k);
        }
        props["encoding"] = json{{"type", "string"}};
        required.push_back("encoding");
    } else {
        props["format"] = json{{"type", "string"}, {"description", "jpeg, png or webp"}};
        required.push_back("format");
    }
    return json{{"$schema", "https://json-schema.org/draft/2020-12/schema"},
                {"title", std::string(foxglove_schema_name(kind))},
                {"description", "a recorded com.robotraconteur.image image as Foxglove's Image panel reads it"},
                {"type", "object"},
                {"properties", std::move(props)},
                {"required", std::move(required)}};
}

std::optional<std::string_view> foxglove_raw_encoding(std::int64_t rr_encoding) {
    switch (rr_encoding) {  // com.robotraconteur.image.ImageEncoding
        case 0x1000: return "rgb8";
        case 0x1001: return "rgba8";
        case 0x1002: return "bgr8";
        case 0x1003: return "bgra8";
        case 0x2000: return "mono8";
        case 0x2001: return "mono16";  // RR image data is little-endian, as Foxglove's mono16
        case 0x3000: return "bayer_rggb8";
        case 0x3001: return "bayer_bggr8";
        case 0x3002: return "bayer_gbrg8";
        case 0x3003: return "bayer_grbg8";
        case 0x4000: return "16UC1";  // depth_u16
        default: return std::nullopt;
    }
}

std::optional<std::string> foxglove_image_message(FoxgloveImageKind kind, const nlohmann::json& value,
                                                  const BinaryArrays& binary, std::uint64_t log_ns) {
    if (!value.is_object() || !value.contains("data") || !value.contains("image_info")) return std::nullopt;
    const json& info = value["image_info"];
    std::vector<std::byte> storage;
    auto bytes = image_bytes(value["data"], binary, storage);
    if (!bytes) return std::nullopt;
    json out{{"timestamp", timestamp(info, log_ns)}, {"frame_id", ""}};
    if (kind == FoxgloveImageKind::raw) {
        if (!info.is_object()) return std::nullopt;
        for (const char* k : {"width", "height", "step", "encoding"})
            if (!info.contains(k) || !info[k].is_number_integer()) return std::nullopt;
        auto encoding = foxglove_raw_encoding(info["encoding"].get<std::int64_t>());
        if (!encoding) return std::nullopt;
        const auto width = info["width"].get<std::int64_t>(), height = info["height"].get<std::int64_t>();
        auto step = info["step"].get<std::int64_t>();
        if (width < 0 || height < 0 || step < 0) return std::nullopt;
        if (step == 0 && height > 0) step = static_cast<std::int64_t>(bytes->size()) / height;  // step not set by the driver
        if (static_cast<std::uint64_t>(step) * static_cast<std::uint64_t>(height) > bytes->size()) return std::nullopt;
        out["width"] = width;
        out["height"] = height;
        out["step"] = step;
        out["encoding"] = std::string(*encoding);
    } else {
        auto format = compressed_format(*bytes);
        if (!format) return std::nullopt;
        out["format"] = std::string(*format);
    }
    out["data"] = base64(*bytes);
    return out.dump();
}

}  // namespace rr::server::record
