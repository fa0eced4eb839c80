// Foxglove image channels (foxglove_image_format.hpp): which types become images, the RR → Foxglove
// encoding names, and the messages (base64 bytes, {sec, nsec} timestamps, what is left out).
#include <catch2/catch.hpp>

#include "robdef/service_definition_set.hpp"
#include "server/record/formats/foxglove_image_format.hpp"

using namespace rr;
namespace record = rr::server::record;
using nlohmann::json;
using rr::DataTypes;
using rr::Enum;
using rr::NumericArray;
using rr::PodArray;
using rr::SharedBytes;
using rr::Structure;
using rr::Value;

namespace {

constexpr const char* kDef = R"(service com.robotraconteur.image

struct Image
    field uint32 width
    field uint8[] data
end

struct CompressedImage
    field uint8[] data
end

struct Other
    field uint8[] data
end
)";

constexpr std::uint64_t kLog = 1764180000ull * 1000000000ull + 5;  // 2025-11-26, 5 ns

// An image value as unpack_value gives it: `data` a uint8 array (or anything else, for the bad cases).
Value image(Value info, Value data) {
    Structure s;
    s.type_name = "com.robotraconteur.image.Image";
    s.set("image_info", std::move(info)).set("data", std::move(data));
    return Value(std::move(s));
}

Structure rgb_info(std::int64_t step = 6) {
    Structure info;
    info.type_name = "com.robotraconteur.image.ImageInfo";
    info.set("width", Value::scalar(std::uint32_t{2}))
        .set("height", Value::scalar(std::uint32_t{1}))
        .set("step", Value::scalar(static_cast<std::uint32_t>(step)))
        .set("encoding", Value(Enum{"com.robotraconteur.image.ImageEncoding", 0x1000}));
    return info;
}

Value bytes(std::initializer_list<std::uint8_t> b) { return Value::array<std::uint8_t>(b); }

Value rgb_image(Value data, std::int64_t step = 6) { return image(Value(rgb_info(step)), std::move(data)); }

}  // namespace

TEST_CASE("foxglove image: the standard image types, not arrays of them or other types") {
    robdef::ServiceDefinitionSet set;
    REQUIRE(set.add_text(kDef, "image.robdef"));
    auto named = [](const char* name, robdef::ContainerKind container = robdef::ContainerKind::none) {
        robdef::TypeDefinition t;
        t.base = DataTypes::namedtype_t;
        t.type_name = name;
        t.container = container;
        return t;
    };
    const char* ctx = "com.robotraconteur.image";
    CHECK(record::foxglove_image_kind(named("Image"), set, ctx) == record::FoxgloveImageKind::raw);
    CHECK(record::foxglove_image_kind(named("com.robotraconteur.image.CompressedImage"), set, "other.svc") ==
          record::FoxgloveImageKind::compressed);
    CHECK_FALSE(record::foxglove_image_kind(named("Image", robdef::ContainerKind::list), set, ctx));
    CHECK_FALSE(record::foxglove_image_kind(named("Other"), set, ctx));
    robdef::TypeDefinition bytes;
    bytes.base = DataTypes::uint8_t;
    bytes.array = robdef::ArrayKind::array;
    CHECK_FALSE(record::foxglove_image_kind(bytes, set, ctx));
}

TEST_CASE("foxglove image: encodings that have a Foxglove name, and those that do not") {
    CHECK(record::foxglove_raw_encoding(0x1000) == "rgb8");
    CHECK(record::foxglove_raw_encoding(0x1003) == "bgra8");
    CHECK(record::foxglove_raw_encoding(0x2001) == "mono16");
    CHECK(record::foxglove_raw_encoding(0x3002) == "bayer_gbrg8");
    CHECK(record::foxglove_raw_encoding(0x4000) == "16UC1");
    CHECK_FALSE(record::foxglove_raw_encoding(0x1004));  // rgba16_16_16_16
    CHECK_FALSE(record::foxglove_raw_encoding(0x2004));  // mono_f32
    CHECK_FALSE(record::foxglove_raw_encoding(0));
}

TEST_CASE("foxglove image: a raw image's message, bytes shared with the received element or copied") {
    const std::byte px[6] = {std::byte{1}, std::byte{2}, std::byte{3}, std::byte{250}, std::byte{251}, std::byte{252}};
    auto received = NumericArray::wrap(DataTypes::uint8_t, SharedBytes::copy_of(std::span<const std::byte>(px)));
    REQUIRE(received);
    auto text = record::foxglove_image_message(record::FoxgloveImageKind::raw, rgb_image(Value(std::move(*received))), kLog);
    REQUIRE(text);
    auto m = json::parse(*text);
    CHECK(m["encoding"] == "rgb8");
    CHECK(m["width"] == 2);
    CHECK(m["height"] == 1);
    CHECK(m["step"] == 6);
    CHECK(m["frame_id"] == "");
    CHECK(m["data"] == "AQID+vv8");
    CHECK(m["timestamp"] == json({{"sec", 1764180000}, {"nsec", 5}}));
    auto from_numbers = record::foxglove_image_message(record::FoxgloveImageKind::raw, rgb_image(bytes({1, 2, 3, 250, 251, 252})), kLog);
    REQUIRE(from_numbers);
    CHECK(json::parse(*from_numbers)["data"] == "AQID+vv8");
}

TEST_CASE("foxglove image: the device's time stamp when it is on the Unix epoch, else the log time") {
    auto with_ts = [](std::int64_t sec, std::int64_t nsec) {
        // data_header.ts as a com.robotraconteur.datetime.TimeSpec2 pod
        PodArray ts("com.robotraconteur.datetime.TimeSpec2", {"seconds", "nanoseconds"});
        REQUIRE(ts.push_back({Value::scalar(sec), Value::scalar(static_cast<std::int32_t>(nsec))}));
        Structure header;
        header.type_name = "com.robotraconteur.sensordata.SensorDataHeader";
        header.set("ts", Value(std::move(ts)));
        auto info = rgb_info();
        info.set("data_header", Value(std::move(header)));
        auto text = record::foxglove_image_message(record::FoxgloveImageKind::raw, image(Value(std::move(info)), bytes({1, 2, 3, 4, 5, 6})), kLog);
        REQUIRE(text);
        return json::parse(*text)["timestamp"];
    };
    CHECK(with_ts(1764179990, 7) == json({{"sec", 1764179990}, {"nsec", 7}}));
    CHECK(with_ts(12, 7) == json({{"sec", 1764180000}, {"nsec", 5}}));  // a clock since boot
}

TEST_CASE("foxglove image: what cannot be shown is left out") {
    CHECK_FALSE(record::foxglove_image_message(record::FoxgloveImageKind::raw, Value(), kLog));
    auto f32 = rgb_info();
    f32.set("encoding", Value(Enum{"com.robotraconteur.image.ImageEncoding", 0x2004}));
    CHECK_FALSE(record::foxglove_image_message(record::FoxgloveImageKind::raw, image(Value(std::move(f32)), bytes({1, 2, 3, 4, 5, 6})), kLog));
    CHECK_FALSE(record::foxglove_image_message(record::FoxgloveImageKind::raw, rgb_image(bytes({1, 2, 3})), kLog));  // short
    CHECK_FALSE(record::foxglove_image_message(record::FoxgloveImageKind::raw, rgb_image(Value::array<double>({1, 2, 3, 4, 5, 6})), kLog));
    Structure empty_info;
    empty_info.type_name = "com.robotraconteur.image.ImageInfo";
    CHECK_FALSE(record::foxglove_image_message(record::FoxgloveImageKind::compressed, image(Value(empty_info), bytes({1, 2, 3, 4})), kLog));
    auto text = record::foxglove_image_message(record::FoxgloveImageKind::compressed, image(Value(empty_info), bytes({0xFF, 0xD8, 0xFF, 0xE0})), kLog);
    REQUIRE(text);
    CHECK(json::parse(*text)["format"] == "jpeg");
    CHECK(json::parse(*text)["data"] == "/9j/4A==");
}

TEST_CASE("foxglove image: the schemas are named as Foxglove looks for them, data base64") {
    auto raw = record::foxglove_image_schema(record::FoxgloveImageKind::raw);
    CHECK(raw["title"] == "foxglove.RawImage");
    CHECK(raw["properties"]["data"]["contentEncoding"] == "base64");
    CHECK(raw["required"] == json({"timestamp", "frame_id", "data", "width", "height", "step", "encoding"}));
    auto compressed = record::foxglove_image_schema(record::FoxgloveImageKind::compressed);
    CHECK(record::foxglove_schema_name(record::FoxgloveImageKind::compressed) == "foxglove.CompressedImage");
    CHECK(compressed["required"] == json({"timestamp", "frame_id", "data", "format"}));
}
