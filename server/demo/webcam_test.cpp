// Simulated webcam images (deterministic, moving) and the webcam device without a network:
// names, frame numbers, CaptureFrameToBuffer into `buffer` and `multidimbuffer`.
#include <catch2/catch.hpp>

#include "server/demo/webcam_device.hpp"

using namespace rr;
using namespace rr::server::demo;

namespace {

std::size_t differing_pixels(const WebcamFrame& a, const WebcamFrame& b) {
    REQUIRE(a.data.size() == b.data.size());
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.data.size(); i += 3)
        n += a.data[i] != b.data[i] || a.data[i + 1] != b.data[i + 1] || a.data[i + 2] != b.data[i + 2];
    return n;
}

std::array<std::uint8_t, 3> pixel(const WebcamFrame& f, int x, int y) {
    const auto* p = &f.data[static_cast<std::size_t>(y) * f.step + static_cast<std::size_t>(x) * 3];
    return {p[0], p[1], p[2]};
}

}  // namespace

TEST_CASE("webcam images: size and layout, deterministic per frame number, moving between frames") {
    const auto f0 = render_webcam_frame(0, 0);
    CHECK(f0.width == 320);
    CHECK(f0.height == 240);
    CHECK(f0.step == 960);
    CHECK(f0.data.size() == 240u * 960u);
    CHECK(render_webcam_frame(0, 0).data == f0.data);  // same frame, same pixels

    const auto f1 = render_webcam_frame(0, 1);
    const auto n01 = differing_pixels(f0, f1);
    CHECK(n01 > 320u * 240u / 2);  // the background scrolls: most pixels change
    const auto g0 = render_webcam_frame(1, 0), g1 = render_webcam_frame(1, 1);
    CHECK(differing_pixels(g0, g1) > 320u * 240u / 10);
    CHECK(differing_pixels(f0, g0) > 320u * 240u / 2);  // the cameras look different

    // The label's black box at the top left, with white digit pixels inside it.
    CHECK(pixel(f0, 0, 0) == std::array<std::uint8_t, 3>{0, 0, 0});
    CHECK(pixel(f0, 3, 3) == std::array<std::uint8_t, 3>{255, 255, 255});  // top-left pixel of "0"
    // The bouncing square: frame 0 of camera 0 has it at (0, 0)…(39, 39), below the label.
    CHECK(pixel(f0, 30, 35) == std::array<std::uint8_t, 3>{255, 220, 0});
    CHECK(pixel(render_webcam_frame(0, 10), 30, 35) != std::array<std::uint8_t, 3>{255, 220, 0});

    const auto small = render_webcam_frame(0, 5, 64, 48);
    CHECK(small.data.size() == 48u * 64u * 3u);
}

TEST_CASE("webcam images: multidim form is [y, x, channel] column-major") {
    const auto f = render_webcam_frame(1, 7, 40, 30);
    const auto m = webcam_multidim(f);
    REQUIRE(m.dims == std::vector<std::uint32_t>{30, 40, 3});
    const auto v = m.array.view<std::uint8_t>();
    REQUIRE(v.size() == 30u * 40u * 3u);
    for (std::size_t y : {0u, 13u, 29u})
        for (std::size_t x : {0u, 21u, 39u})
            for (std::size_t c = 0; c < 3; ++c) CHECK(v[y + 30 * (x + 40 * c)] == f.data[y * f.step + x * 3 + c]);
}

TEST_CASE("webcam device: names, frames advancing per tick, capture to the memories") {
    auto host = WebcamHostDevice::create();
    REQUIRE(host);
    auto& h = **host;
    REQUIRE(h.camera_count() == 2);
    CHECK(h.camera(0)->name() == "Left");
    CHECK(h.camera(1)->name() == "Right");
    auto names = h.object()->property_value("WebcamNames");
    REQUIRE(names);
    const auto* map = names->get_if<MapInt32>();
    REQUIRE(map);
    REQUIRE(map->entries.size() == 2);
    CHECK(*map->find(0) == Value("Left"));
    CHECK(*map->find(1) == Value("Right"));
    CHECK(*h.camera(1)->object()->property_value("Name") == Value("Right"));

    auto& cam = *h.camera(0);
    CHECK(cam.frame_number() == 0);
    const auto a = cam.capture();
    h.tick();
    h.tick();
    CHECK(cam.frame_number() == 2);
    CHECK(h.camera(1)->frame_number() == 2);
    const auto b = cam.capture();
    CHECK(b.number == 2);
    CHECK(b.data == render_webcam_frame(0, 2).data);
    CHECK(differing_pixels(a, b) > 0);
    CHECK_FALSE(cam.streaming());
    CHECK(cam.stats().frames_sent == 0);  // not streaming: nothing sent

    // The memories hold frame 0 from the start, then what CaptureFrameToBuffer rendered.
    auto buffer = cam.object()->memory("buffer").value();
    auto multidim = cam.object()->memory("multidimbuffer").value();
    {
        const Value c = buffer->contents();
        const auto* arr = c.get_if<NumericArray>();
        REQUIRE(arr);
        CHECK(std::vector<std::uint8_t>(arr->view<std::uint8_t>().begin(), arr->view<std::uint8_t>().end()) == a.data);
    }
    const auto captured = cam.capture_to_buffer();
    CHECK(captured.number == 2);
    CHECK(buffer->dimensions() == std::vector<std::uint64_t>{240u * 960u});
    const Value c = buffer->contents();
    const auto* arr = c.get_if<NumericArray>();
    REQUIRE(arr);
    CHECK(std::vector<std::uint8_t>(arr->view<std::uint8_t>().begin(), arr->view<std::uint8_t>().end()) == b.data);
    CHECK(multidim->dimensions() == std::vector<std::uint64_t>{240, 320, 3});
    const Value md = multidim->contents();
    const auto* m = md.get_if<MultiDimArray>();
    REQUIRE(m);
    CHECK(*m == webcam_multidim(b));
}
