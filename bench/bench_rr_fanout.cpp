// rr_bench_rr_fanout: raw RR fan-out (issue 14). N native clients (rr::client::Client) in one process,
// on one io_context, each connected to a wire of the bench service, normally through the gateway over
// rr+ws: the path of the dashboard's wasm client, with the native client standing in for the browsers.
//
// Usage:
//   rr_bench_rr_fanout --url URL --clients N [--seconds S] [--hz H] [--threads T] [--member M]
//     URL: the bench service (rr+ws://GATEWAY/?service=bench, or rr+tcp, or the device itself).
//     Connects N clients (at most 64 connecting at once) with T IO threads (default 1), then the wire M
//     (default Ticks, values [stamp_us, sequence, ...]) on each; once every client has a value, counts
//     for S seconds (default 5). Prints one JSON line with the keys of rr_bench_ws_load's fanout row
//     (delivered values/s, expected N × H, delivered_of_sent, latency from the device's stamp p50/p99/max,
//     loadgen_cpu_pct) plus per-client rates and the load generator's CPU µs and context switches per value.
#include <condition_variable>
#include <iostream>
#include <mutex>


#include "bench/bench_common.hpp"
#include "server/client/client.hpp"

using namespace rr;
using clock_type = std::chrono::steady_clock;

namespace {

/// One client's wire values; written on its connection's strand, read by main after measuring.
struct Sink {
    std::mutex m;
    bool got_value = false;
    std::vector<double> latency_us;
    double first_seq = -1, last_seq = -1;
};

struct Shared {
    std::mutex m;
    std::condition_variable cv;
    std::size_t with_value = 0;
    std::atomic<bool> measuring{false};
};

}  // namespace

int main(int argc, char** argv) {
    std::string url, member = "Ticks";
    std::size_t clients = 10;
    double seconds = 5, hz = 100;
    unsigned threads = 1;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (i + 1 >= argc) {
            std::cerr << "usage: " << argv[0] << " --url URL --clients N [--seconds S] [--hz H] [--threads T] [--member M]\n";
            return 2;
        }
        std::string v = argv[++i];
        if (a == "--url") url = v;
        else if (a == "--clients") clients = std::stoul(v);
        else if (a == "--seconds") seconds = std::stod(v);
        else if (a == "--hz") hz = std::stod(v);
        else if (a == "--threads") threads = static_cast<unsigned>(std::stoul(v));
        else if (a == "--member") member = v;
        else {
            std::cerr << "unknown option " << a << "\n";
            return 2;
        }
    }
    if (url.empty()) {
        std::cerr << "need --url\n";
        return 2;
    }
    bench::raise_fd_limit();

    // Declared before the IO threads, so that handlers still running at exit find them.
    Shared shared;
    std::vector<std::unique_ptr<Sink>> sinks;
    for (std::size_t i = 0; i < clients; ++i) sinks.push_back(std::make_unique<Sink>());
    client::IoThreads io(threads);
    std::vector<std::shared_ptr<client::Client>> conns(clients);
    std::vector<client::WireConnection> wires(clients);
    std::string first_error;
    std::size_t failed = 0;

    // Connect: at most 64 in progress, as the JSON load generator (the listen backlog is finite).
    const auto open_t0 = clock_type::now();
    {
        std::size_t next = 0, in_progress = 0, done = 0;
        std::unique_lock lock(shared.m);
        while (done < clients) {
            while (next < clients && in_progress < 64) {
                const std::size_t k = next++;
                ++in_progress;
                lock.unlock();
                client::Client::connect(io.executor(), url, {}, [&, k](Result<std::shared_ptr<client::Client>> r) {
                    std::lock_guard l(shared.m);
                    if (r) conns[k] = std::move(*r);
                    else if (first_error.empty()) first_error = "connect: " + r.error().message;
                    --in_progress;
                    ++done;
                    shared.cv.notify_all();
                });
                lock.lock();
            }
            shared.cv.wait(lock, [&] { return (next < clients && in_progress < 64) || done == clients; });
        }
    }
    // Wires, one blocking connect after the other (not from a strand: blocking calls may not run there).
    for (std::size_t k = 0; k < clients; ++k) {
        if (!conns[k]) {
            ++failed;
            continue;
        }
        auto w = conns[k]->root().wire_connect(member);
        if (!w) {
            ++failed;
            if (first_error.empty()) first_error = "wire_connect: " + w.error().message;
            continue;
        }
        Sink* sink = sinks[k].get();
        w->set_value_handler([sink, &shared](const WireValue& v) {
            const double now = bench::wall_clock_us();
            const auto* a = v.value.get_if<NumericArray>();
            if (!a || a->size() < 2) return;
            const auto items = a->view<double>();
            if (items[1] < 0) return;
            bool first = false;
            {
                std::lock_guard l(sink->m);
                first = !sink->got_value;
                sink->got_value = true;
                if (shared.measuring.load(std::memory_order_relaxed)) {
                    if (sink->first_seq < 0) sink->first_seq = items[1];
                    sink->last_seq = items[1];
                    sink->latency_us.push_back(now - items[0]);
                }
            }
            if (first) {
                std::lock_guard l(shared.m);
                ++shared.with_value;
                shared.cv.notify_all();
            }
        });
        wires[k] = std::move(*w);
    }
    const std::size_t opened = clients - failed;
    const double open_s = bench::elapsed_us(open_t0, clock_type::now()) / 1e6;

    // Wait (at most 30 s) until every open client has its first value, then measure.
    {
        std::unique_lock lock(shared.m);
        shared.cv.wait_for(lock, std::chrono::seconds(30), [&] { return shared.with_value >= opened; });
    }
    for (auto& s : sinks) {
        std::lock_guard l(s->m);
        s->latency_us.reserve(static_cast<std::size_t>(hz * seconds * 1.2));
    }
    const auto cpu0 = bench::CpuSnapshot::now();
    const auto t0 = clock_type::now();
    shared.measuring = true;
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    shared.measuring = false;
    const double wall = bench::elapsed_us(t0, clock_type::now());
    const auto cpu1 = bench::CpuSnapshot::now();

    std::vector<double> latency, per_client;
    double device_sent = 0;  // per client: values the device sent in its window (wires keep the newest only)
    std::uint64_t delivered = 0;
    for (std::size_t k = 0; k < clients; ++k) {
        if (!wires[k]) continue;
        std::lock_guard l(sinks[k]->m);
        const auto& s = *sinks[k];
        latency.insert(latency.end(), s.latency_us.begin(), s.latency_us.end());
        delivered += s.latency_us.size();
        per_client.push_back(double(s.latency_us.size()) * 1e6 / wall);
        if (s.first_seq >= 0) device_sent += s.last_seq - s.first_seq + 1;
    }
    std::sort(per_client.begin(), per_client.end());
    const double n = double(delivered);
    std::cout << nlohmann::json{{"mode", "rr_fanout"},
                                {"url", url},
                                {"member", member},
                                {"clients", clients},
                                {"threads", threads},
                                {"opened", opened},
                                {"failed", failed},
                                {"with_value", shared.with_value},
                                {"open_s", open_s},
                                {"seconds", wall / 1e6},
                                {"delivered_per_s", n * 1e6 / wall},
                                {"expected_per_s", double(opened) * hz},
                                {"delivered_of_sent", device_sent > 0 ? n / device_sent : 0.0},
                                {"per_client_per_s_min", per_client.empty() ? 0.0 : per_client.front()},
                                {"per_client_per_s_median", bench::percentile(per_client, 0.5)},
                                {"p50_us", bench::percentile(latency, 0.5)},
                                {"p99_us", bench::percentile(latency, 0.99)},
                                {"max_us", latency.empty() ? 0.0 : *std::max_element(latency.begin(), latency.end())},
                                {"loadgen_cpu_pct", 100.0 * (cpu1.cpu_us - cpu0.cpu_us) / wall},
                                {"loadgen_cpu_us_per_value", n > 0 ? (cpu1.cpu_us - cpu0.cpu_us) / n : 0.0},
                                {"loadgen_vcsw_per_value", n > 0 ? double(cpu1.vcsw - cpu0.vcsw) / n : 0.0},
                                {"error", first_error}}
                     .dump()
              << std::endl;

    for (auto& w : wires)
        if (w) w.set_value_handler(nullptr);
    for (auto& c : conns)
        if (c) c->close();
    return 0;
}
