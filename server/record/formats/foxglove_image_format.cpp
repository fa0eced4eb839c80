#include "server/record/formats/foxglove_image_format.hpp"

#include <openssl/evp.h>

#include <cstddef>
#include <span>
#include <vector>

#include "core/value/pack_value.hpp"
#include "server/record/formats/formats.hpp"

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

// The image's bytes: its `data`, a uint8 array (shared with the received element when it has more than
// one byte).
std::optional<SharedBytes> image_bytes(const Value* data) {
    const auto* a = data ? data->get_if<NumericArray>() : nullptr;
    if (!a || a->type() != DataTypes::uint8_t) return std::nullopt;
    return a->to_bytes();
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

// An integer field of `v` (a struct, or a scalar pod), or nothing.
std::optional<std::int64_t> integer_field(const Value* v, std::string_view name) {
    const Value* f = v ? v->field(name) : nullptr;
    if (!f) return std::nullopt;
    auto i = f->as<std::int64_t>();
    if (!i) return std::nullopt;
    return *i;
}

json timestamp(const Value* image_info, std::uint64_t log_ns) {
    std::uint64_t ns = log_ns;
    const Value* header = image_info ? image_info->field("data_header") : nullptr;
    const Value* ts = header ? header->field("ts") : nullptr;
    const auto sec = integer_field(ts, "seconds"), nsec = integer_field(ts, "nanoseconds");
    if (sec && nsec) {
        const auto log_sec = static_cast<std::int64_t>(log_ns / kNsPerSec);
        if (*sec > 0 && *nsec >= 0 && *nsec < static_cast<std::int64_t>(kNsPerSec) && *sec > log_sec - kDaySeconds &&
            *sec < log_sec + kDaySeconds)
            ns = static_cast<std::uint64_t>(*sec) * kNsPerSec + static_cast<std::uint64_t>(*nsec);
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

std::optional<std::string> foxglove_image_message(FoxgloveImageKind kind, const Value& image, std::uint64_t log_ns) {
    const Value* info = image.field("image_info");
    auto data = image_bytes(image.field("data"));
    if (!info || !data) return std::nullopt;
    const auto bytes = data->bytes();
    json out{{"timestamp", timestamp(info, log_ns)}, {"frame_id", ""}};
    if (kind == FoxgloveImageKind::raw) {
        const auto width = integer_field(info, "width"), height = integer_field(info, "height");
        auto step = integer_field(info, "step");
        const auto rr_encoding = integer_field(info, "encoding");
        if (!width || !height || !step || !rr_encoding) return std::nullopt;
        auto encoding = foxglove_raw_encoding(*rr_encoding);
        if (!encoding) return std::nullopt;
        if (*width < 0 || *height < 0 || *step < 0) return std::nullopt;
        if (*step == 0 && *height > 0) *step = static_cast<std::int64_t>(bytes.size()) / *height;  // step not set by the driver
        if (static_cast<std::uint64_t>(*step) * static_cast<std::uint64_t>(*height) > bytes.size()) return std::nullopt;
        out["width"] = *width;
        out["height"] = *height;
        out["step"] = *step;
        out["encoding"] = std::string(*encoding);
    } else {
        auto format = compressed_format(bytes);
        if (!format) return std::nullopt;
        out["format"] = std::string(*format);
    }
    out["data"] = base64(bytes);
    return out.dump();
}

std::optional<FoxgloveImageKind> foxglove_image_kind_of(const RecordedMember& m) {
    if (m.kind == RecordedKind::event) return std::nullopt;
    const auto& t = *m.target;
    return foxglove_image_kind(t.member->type, t.types->set(), t.context());
}

MappedChannel foxglove_image_channel(const RecordedMember& m, FoxgloveImageKind kind) {
    auto metadata = m.metadata;
    metadata[channel_key::foxglove] = kind == FoxgloveImageKind::raw
                                          ? "RawImage of the encodings rgb888 rgba8888 bgr888 bgra8888 mono8 mono16 "
                                            "bayer_*8888 depth_u16; other frames are not on this channel"
                                          : "CompressedImage of JPEG, PNG or WebP bytes; other frames are not on this channel";
    return MappedChannel{m.topic + "/foxglove", "json", std::string(foxglove_schema_name(kind)), "jsonschema",
                         foxglove_image_schema(kind).dump(), std::move(metadata)};
}

std::optional<std::string> foxglove_image_message(const gateway::JsonApi& api, const RecordedMember& m, FoxgloveImageKind kind,
                                                  const MessageEntry& entry, std::uint64_t log_ns) {
    const auto& t = *m.target;
    const MessageElement* el = m.kind == RecordedKind::wire   ? entry.find("packet")
                               : m.kind == RecordedKind::pipe ? (entry.elements.empty() ? nullptr : &entry.elements[0])
                                                              : entry.find("value");
    if (!el) return std::nullopt;
    // One conversion: the element to a value whose pixel bytes are the element's, read into the message.
    auto image = unpack_value(*el, t.member->type, t.types->set(), t.context(), api.options().limits);
    if (!image) return std::nullopt;
    return foxglove_image_message(kind, *image, log_ns);
}

// --- the format ------------------------------------------------------------------------------------

namespace {

class FoxgloveImageEncoder : public FormatEncoder {
public:
    explicit FoxgloveImageEncoder(const FormatContext& context) : context_(context) {
        for (const auto& m : context_.members) kinds_.push_back(foxglove_image_kind_of(m));
    }

    Result<void> open_file(FormatFile& file) override {
        channels_.assign(context_.members.size(), std::nullopt);
        std::optional<std::uint16_t> schemas[2];  // by kind, added once a file
        for (std::size_t i = 0; i < context_.members.size(); ++i) {
            if (!kinds_[i]) continue;
            const auto c = foxglove_image_channel(context_.members[i], *kinds_[i]);
            auto& sid = schemas[*kinds_[i] == FoxgloveImageKind::raw ? 0 : 1];
            if (!sid) {
                auto id = file.add_schema(c.schema_name, c.schema_encoding, c.schema);
                if (!id) return id.take_error();
                sid = *id;
            }
            auto cid = file.add_channel(*sid, c.topic, c.message_encoding, c.metadata);
            if (!cid) return cid.take_error();
            channels_[i] = *cid;
        }
        return {};
    }

    Result<void> write(const RecordedEntry& e, MessageOut& out) override {
        if (!channels_[e.member]) return {};
        auto text = foxglove_image_message(context_.api, context_.members[e.member], *kinds_[e.member], e.entry.entry(), e.log_ns);
        if (!text) return {};
        return out.write(*channels_[e.member], *text);
    }

private:
    const FormatContext& context_;
    std::vector<std::optional<FoxgloveImageKind>> kinds_;  // per member: an image, or not
    std::vector<std::optional<std::uint16_t>> channels_;   // per member, in the open file
};

class FoxgloveImageFormat : public RecordingFormat {
public:
    std::string_view name() const noexcept override { return "foxglove_image"; }
    bool is_encoding() const noexcept override { return false; }
    bool enabled(const RecordingSpec& spec) const override { return spec.encodes("json") && spec.foxglove_images; }
    std::unique_ptr<FormatEncoder> encoder(const FormatContext& context) const override {
        return std::make_unique<FoxgloveImageEncoder>(context);
    }
};

}  // namespace

std::shared_ptr<const RecordingFormat> foxglove_image_format() { return std::make_shared<FoxgloveImageFormat>(); }

}  // namespace rr::server::record
