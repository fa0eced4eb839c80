// Simulated webcam images for the demo device `webcam` (experimental.createwebcam): deterministic
// from (camera, frame number), moving from frame to frame, so tests can check pixels.
//
// Image: width × height pixels, 3 bytes per pixel in R, G, B order, rows top to bottom, step = width·3
// bytes per row (no padding): pixel (x, y) channel c is data[y·step + x·3 + c].
// Content: a coloured background that scrolls (camera 0: a gradient, camera 1: diagonal stripes), a
// 40-pixel square bouncing around (yellow / magenta), and a black label at the top left showing
// "<camera>-<frame number>" in white digits (3×5 font, 3× scaled).
#pragma once

#include <cstdint>
#include <vector>

#include "core/value/value.hpp"

namespace rr::server::demo {

struct WebcamFrame {
    std::int32_t width = 0, height = 0, step = 0;
    std::uint64_t number = 0;         ///< frame number it was rendered for
    std::vector<std::uint8_t> data;   ///< height · step bytes
};

/// Renders frame `number` of camera `camera` (0 or 1; others reuse camera 1's look). width and height
/// are clamped to 16 … 4096.
WebcamFrame render_webcam_frame(int camera, std::uint64_t number, std::int32_t width = 320, std::int32_t height = 240);

/// experimental.createwebcam.WebcamImage {width, height, step, data}.
Value webcam_image_value(const WebcamFrame& frame);
/// experimental.createwebcam.WebcamImage_size {width, height, step}.
Value webcam_image_size_value(const WebcamFrame& frame);
/// The `multidimbuffer` contents: uint8 dims {height, width, 3}, column-major (wire.md: item (y, x, c)
/// at y + height·(x + width·c)); a client indexing [y, x, c] gets the pixel's channel c.
MultiDimArray webcam_multidim(const WebcamFrame& frame);

}  // namespace rr::server::demo
