#include "server/demo/webcam_image.hpp"

#include <algorithm>
#include <array>
#include <string>

#include "robdef/builtin/experimental_createwebcam.hpp"

namespace rr::server::demo {

namespace {

// 3×5 glyphs, one row per entry, bit 2 = left column.
constexpr std::array<std::array<std::uint8_t, 5>, 11> kGlyphs = {{
    {7, 5, 5, 5, 7},  // 0
    {2, 6, 2, 2, 7},  // 1
    {7, 1, 7, 4, 7},  // 2
    {7, 1, 7, 1, 7},  // 3
    {5, 5, 7, 1, 1},  // 4
    {7, 4, 7, 1, 7},  // 5
    {7, 4, 7, 5, 7},  // 6
    {7, 1, 2, 2, 2},  // 7
    {7, 5, 7, 5, 7},  // 8
    {7, 5, 7, 1, 7},  // 9
    {0, 0, 7, 0, 0},  // -
}};
constexpr int kScale = 3;

/// 0 … span, back and forth.
std::int32_t triangle(std::uint64_t t, std::int32_t span) {
    if (span <= 0) return 0;
    const std::uint64_t period = 2 * static_cast<std::uint64_t>(span);
    const std::uint64_t p = t % period;
    return static_cast<std::int32_t>(p <= static_cast<std::uint64_t>(span) ? p : period - p);
}

void put(WebcamFrame& f, std::int32_t x, std::int32_t y, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    if (x < 0 || y < 0 || x >= f.width || y >= f.height) return;
    auto* p = &f.data[static_cast<std::size_t>(y) * f.step + static_cast<std::size_t>(x) * 3];
    p[0] = r;
    p[1] = g;
    p[2] = b;
}

}  // namespace

WebcamFrame render_webcam_frame(int camera, std::uint64_t number, std::int32_t width, std::int32_t height) {
    WebcamFrame f;
    f.width = std::clamp(width, 16, 4096);
    f.height = std::clamp(height, 16, 4096);
    f.step = f.width * 3;
    f.number = number;
    f.data.resize(static_cast<std::size_t>(f.height) * f.step);
    const bool first = camera == 0;

    // Background.
    for (std::int32_t y = 0; y < f.height; ++y) {
        for (std::int32_t x = 0; x < f.width; ++x) {
            if (first) {
                const auto r = static_cast<std::uint8_t>((x * 255 / (f.width - 1) + 3 * number) & 0xFF);
                const auto g = static_cast<std::uint8_t>(y * 255 / (f.height - 1));
                put(f, x, y, r, g, 96);
            } else {
                const bool band = (((static_cast<std::uint64_t>(x) + y + 4 * number) / 16) & 1) != 0;
                put(f, x, y, band ? 40 : 90, band ? 60 : 110, band ? 150 : 200);
            }
        }
    }

    // Bouncing square.
    constexpr std::int32_t kBox = 40;
    const std::int32_t bx = triangle(number * 7 + (first ? 0 : 50), f.width - kBox);
    const std::int32_t by = triangle(number * 5 + (first ? 0 : 30), f.height - kBox);
    for (std::int32_t y = by; y < by + kBox; ++y)
        for (std::int32_t x = bx; x < bx + kBox; ++x) {
            if (first) put(f, x, y, 255, 220, 0);
            else put(f, x, y, 230, 0, 200);
        }

    // Label "<camera>-<number>".
    const std::string label = std::to_string(camera) + "-" + std::to_string(number);
    const std::int32_t glyph_w = 3 * kScale, gap = kScale;
    const std::int32_t label_w = static_cast<std::int32_t>(label.size()) * (glyph_w + gap) + gap;
    const std::int32_t label_h = 5 * kScale + 2 * gap;
    for (std::int32_t y = 0; y < label_h; ++y)
        for (std::int32_t x = 0; x < label_w; ++x) put(f, x, y, 0, 0, 0);
    for (std::size_t i = 0; i < label.size(); ++i) {
        const auto& glyph = kGlyphs[label[i] == '-' ? 10 : static_cast<std::size_t>(label[i] - '0')];
        const std::int32_t ox = gap + static_cast<std::int32_t>(i) * (glyph_w + gap), oy = gap;
        for (std::int32_t row = 0; row < 5; ++row)
            for (std::int32_t col = 0; col < 3; ++col)
                if (glyph[static_cast<std::size_t>(row)] & (4 >> col))
                    for (std::int32_t sy = 0; sy < kScale; ++sy)
                        for (std::int32_t sx = 0; sx < kScale; ++sx)
                            put(f, ox + col * kScale + sx, oy + row * kScale + sy, 255, 255, 255);
    }
    return f;
}

Value webcam_image_value(const WebcamFrame& frame) {
    Structure s;
    s.type_name = std::string(robdef::kExperimentalWebcamImage);
    s.set("width", Value::scalar<std::int32_t>(frame.width));
    s.set("height", Value::scalar<std::int32_t>(frame.height));
    s.set("step", Value::scalar<std::int32_t>(frame.step));
    s.set("data", Value(NumericArray::from<std::uint8_t>(std::span<const std::uint8_t>(frame.data))));
    return Value(std::move(s));
}

Value webcam_image_size_value(const WebcamFrame& frame) {
    Structure s;
    s.type_name = std::string(robdef::kExperimentalWebcamImageSize);
    s.set("width", Value::scalar<std::int32_t>(frame.width));
    s.set("height", Value::scalar<std::int32_t>(frame.height));
    s.set("step", Value::scalar<std::int32_t>(frame.step));
    return Value(std::move(s));
}

MultiDimArray webcam_multidim(const WebcamFrame& frame) {
    const std::size_t h = static_cast<std::size_t>(frame.height), w = static_cast<std::size_t>(frame.width);
    std::vector<std::uint8_t> out(h * w * 3);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x)
            for (std::size_t c = 0; c < 3; ++c)
                out[y + h * (x + w * c)] = frame.data[y * static_cast<std::size_t>(frame.step) + x * 3 + c];
    MultiDimArray m;
    m.dims = {static_cast<std::uint32_t>(h), static_cast<std::uint32_t>(w), 3};
    m.array = NumericArray::adopt<std::uint8_t>(std::move(out));
    return m;
}

}  // namespace rr::server::demo
