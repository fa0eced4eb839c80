// rr_bench_json_text: what rendering one value as JSON text costs the gateway, on the general path
// (unpack_value -> value_to_json -> nlohmann's dump) and on the direct one (core/json/element_json_plan:
// the value written straight from the element by the type's compiled plan, as the gateway does). The gateway renders each wire value, event and
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

#include "core/json/element_json_plan.hpp"
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

// A robot controller's state wire, after com.robotraconteur.robotics.robot.RobotState (its shapes, not
// its text): a timestamp pod, enums, joint arrays and tool poses.
constexpr const char* kBenchRobdef = R"(service bench.robot
stdver 0.10
enum Mode
    halt = 0,
    run = 3
end
namedarray Vector3
    field double x
    field double y
    field double z
end
namedarray Quaternion
    field double w
    field double x
    field double y
    field double z
end
namedarray Pose
    field Quaternion orientation
    field Vector3 position
end
pod TimeSpec3
    field int64 microseconds
end
struct RobotState
    field TimeSpec3 ts
    field uint64 seqno
    field Mode command_mode
    field Mode operational_mode
    field uint64 robot_state_flags
    field double[] joint_position
    field double[] joint_velocity
    field double[] joint_effort
    field double[] joint_position_command
    field double[] joint_velocity_command
    field Pose[] kin_chain_tcp
    field bool trajectory_running
    field string name
end
)";

nlohmann::json pose_json(double k) {
    return {{"orientation", {{"w", 0.7071067811865476}, {"x", 0.0}, {"y", 0.7071067811865475}, {"z", k / 10}}},
            {"position", {{"x", 0.5 + k}, {"y", -0.25}, {"z", 1.125}}}};
}

nlohmann::json robot_state_json(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> real(-3.14159, 3.14159);
    auto joints = [&] {
        nlohmann::json a = nlohmann::json::array();
        for (int i = 0; i < 6; ++i) a.push_back(real(rng));
        return a;
    };
    return {{"ts", {{"microseconds", 1764000000123456}}},
            {"seqno", 123456},
            {"command_mode", 3},
            {"operational_mode", 0},
            {"robot_state_flags", 0x10003},
            {"joint_position", joints()},
            {"joint_velocity", joints()},
            {"joint_effort", joints()},
            {"joint_position_command", joints()},
            {"joint_velocity_command", joints()},
            {"kin_chain_tcp", {pose_json(1)}},
            {"trajectory_running", false},
            {"name", "arm_1"}};
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
    rr::robdef::ServiceDefinitionSet types;
    if (!types.add_text(kBenchRobdef, "bench.robdef")) return 1;
    constexpr std::string_view ctx = "bench.robot";
    struct Case {
        std::string type;
        rr::MessageElement element;
        std::size_t items;
    };
    std::vector<Case> cases;
    auto numeric = [&](std::string type, rr::MessageElement e) {
        const std::size_t items = e.data.size() / rr::data_type_size(e.type);
        cases.push_back({std::move(type), std::move(e), items});
    };
    numeric("double", element_of<double>(1, rng));
    numeric("double[]", element_of<double>(16, rng));
    numeric("double[]", element_of<double>(1000, rng));
    numeric("int32[]", element_of<std::int32_t>(1000, rng));
    numeric("uint8[]", element_of<std::uint8_t>(640 * 480 * 3, rng));  // a camera frame
    auto named = [&](std::string type, const nlohmann::json& j, std::size_t items) {
        auto t = rr::parse_type_string(type);
        if (!t) return false;
        auto v = rr::value_from_json(j, *t, types, ctx);
        if (!v) return false;
        auto e = rr::pack_value(*v, *t, "value", types, ctx);
        if (!e) return false;
        cases.push_back({std::move(type), std::move(*e), items});
        return true;
    };
    nlohmann::json poses = nlohmann::json::array();
    for (int i = 0; i < 100; ++i) poses.push_back(pose_json(i));
    if (!named("string", "tool 1: \"gripper\" ready", 1) || !named("RobotState", robot_state_json(rng), 1) ||
        !named("Pose[]", poses, 100))
        return 1;
    for (const auto& c : cases) {
        auto type = rr::parse_type_string(c.type);
        if (!type) return 1;
        auto plan = rr::element_json_text::Plan::compile(*type, types, ctx);
        if (!plan) return 1;
        std::string direct_text, general_text;
        auto general = [&] {
            auto v = rr::unpack_value(c.element, *type, types, ctx);
            auto j = rr::value_to_json(*v, *type, types, ctx);
            general_text = j->dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
            return general_text.size();
        };
        auto direct = [&] {
            std::string out;
            plan->append(out, c.element);
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
                           {"items", c.items},
                           {"text_bytes", direct_text.size()},
                           {"general_us", g},
                           {"direct_us", d},
                           {"speedup", g / d}};
        std::cout << row.dump() << std::endl;
    }
    return 0;
}
