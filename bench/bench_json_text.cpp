// rr_bench_json_text: what rendering one value as JSON text costs the gateway, on the general path
// (unpack_value -> value_to_json -> nlohmann's dump) and on the direct one (core/json/element_json_text:
// numeric types written straight from the element). The gateway renders each wire value, event and
// pipe packet once for all its JSON subscribers; this is that once. Prints one JSON line per type:
// µs per value on each path (the median of 5 batches), their ratio, and the text's size.
//
// Usage: rr_bench_json_text [--seconds S]   (per path and type, default 0.3)
#include <algorithm>
#include <chrono>
#include <cstring>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/json/element_json_text.hpp"
#include "core/json/value_json.hpp"
#include "core/value/numeric_array.hpp"
#include "core/value/pack_value.hpp"
#include "robdef/service_definition_set.hpp"
#include "core/value/var_type.hpp"

namespace {

using Clock = std::chrono::steady_clock;

template <class T>
rr::MessageElement element_of(std::size_t n, std::mt19937_64& rng) {
    rr::MessageElement e;
    e.name = "value";
    e.type = rr::numeric_type_v<T>;
    std::vector<std::byte> bytes(n * sizeof(T));
    std::uniform_real_distribution<double> real(-1000, 1000);
    for (std::size_t i = 0; i < n; ++i) {
        T v;
        if constexpr (std::is_floating_point_v<T>)
            v = static_cast<T>(real(rng));
        else
            v = static_cast<T>(rng());
        rr::detail::store_item<T>(bytes.data() + i * sizeof(T), v);
    }
    e.data = rr::SharedBytes::adopt(std::move(bytes));
    return e;
}

// Median µs per call of `render` over 5 batches of about `seconds`/5 each.
template <class Render>
double us_per_value(double seconds, Render&& render) {
    std::size_t sink = 0;
    std::size_t n = 1;
    for (;;) {  // calibrate: a batch of n takes at least 1/50 of the time
        const auto t0 = Clock::now();
        for (std::size_t i = 0; i < n; ++i) sink += render();
        if (std::chrono::duration<double>(Clock::now() - t0).count() >= seconds / 50 || n >= (1u << 30)) break;
        n *= 2;
    }
    const std::size_t batch = std::max<std::size_t>(1, n * 10);
    std::vector<double> us;
    for (int b = 0; b < 5; ++b) {
        const auto t0 = Clock::now();
        for (std::size_t i = 0; i < batch; ++i) sink += render();
        us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / static_cast<double>(batch));
    }
    std::sort(us.begin(), us.end());
    if (sink == 42) std::cerr << "";  // keep the renders
    return us[2];
}

}  // namespace

int main(int argc, char** argv) {
    double seconds = 0.3;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--seconds" && i + 1 < argc) {
            seconds = std::stod(argv[++i]);
        } else {
            std::cerr << "usage: rr_bench_json_text [--seconds S]\n";
            return 2;
        }
    }
    std::mt19937_64 rng(1);
    const rr::robdef::ServiceDefinitionSet no_types;
    struct Case {
        std::string type;
        rr::MessageElement element;
    };
    std::vector<Case> cases;
    cases.push_back({"double", element_of<double>(1, rng)});
    cases.push_back({"double[]", element_of<double>(16, rng)});
    cases.push_back({"double[]", element_of<double>(1000, rng)});
    cases.push_back({"int32[]", element_of<std::int32_t>(1000, rng)});
    cases.push_back({"uint8[]", element_of<std::uint8_t>(640 * 480 * 3, rng)});  // a camera frame
    for (const auto& c : cases) {
        auto type = rr::parse_type_string(c.type);
        if (!type) return 1;
        std::string direct_text, general_text;
        auto general = [&] {
            auto v = rr::unpack_value(c.element, *type, no_types, "");
            auto j = rr::value_to_json(*v, *type, no_types, "");
            general_text = j->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
            return general_text.size();
        };
        auto direct = [&] {
            std::string out;
            rr::element_json_text::append(out, c.element, *type);
            direct_text = std::move(out);
            return direct_text.size();
        };
        const double g = us_per_value(seconds, general);
        const double d = us_per_value(seconds, direct);
        if (direct_text != general_text) {
            std::cerr << "rr_bench_json_text: the two paths disagree for " << c.type << "\n";
            return 1;
        }
        nlohmann::json row{{"row", "json_text"},
                           {"type", c.type},
                           {"items", c.element.data.size() / rr::data_type_size(c.element.type)},
                           {"text_bytes", direct_text.size()},
                           {"general_us", g},
                           {"direct_us", d},
                           {"speedup", g / d}};
        std::cout << row.dump() << std::endl;
    }
    return 0;
}
