// rr_bench_client: drives experimental.bench with our native client (rr::client::Client) and prints one
// JSON line per measured operation (bench_common.hpp: latency_row).
//
// Usage:
//   rr_bench_client --url URL [--label L] [--count N] [--ops a,b,...] [--caller-io 1]
//   --caller-io 1: no worker thread; the calling thread runs the connection's I/O while each blocking
//   call waits (ClientOptions::caller_runs_io). Blocking ops only (nop, echoN, get, set, peek).
// URL: rr+tcp://… or rr+ws://… naming the bench service (directly, or through a gateway).
// Operations (default: all):
//   nop        blocking Nop() round trip             nop_async  Nop() chained on the strand (async layer)
//   echo10 / echo1000 / echo100000  blocking Echo(d) with that many doubles
//   get / set  property Value                         peek       wire Ticks PeekInValue
//   wire       one-way latency of Ticks values at 500 Hz (stamped by the service, same host clock)
//   wire_rate  Ticks sent back to back: values delivered per second (wires keep only the newest)
//   pipe       packets/s on Packets with acks requested, until every ack arrived
//   memory     read and write of the whole Buffer (10 MiB), MB/s
// N is the Nop count (default 5000); Echo 1,000 uses N/2, Echo 100,000 N/50 (at least 20).
#include <atomic>
#include <condition_variable>
#include <iostream>
#include <mutex>
#include <sstream>

#include "bench/bench_common.hpp"
#include "server/client/client.hpp"

using namespace rr;
using namespace std::chrono_literals;
using clock_type = std::chrono::steady_clock;
using rr::bench::CpuSnapshot;
using rr::bench::elapsed_us;
using rr::bench::latency_row;

namespace {

std::string g_label;

void emit(nlohmann::json row) {
    row["label"] = g_label;
    std::cout << row.dump() << std::endl;
}

[[noreturn]] void die(const std::string& what, const RRError& e) {
    std::cerr << "[bench_client] " << what << ": " << e.name << ": " << e.message << std::endl;
    std::exit(1);
}

template <class T>
T must(Result<T> r, const std::string& what) {
    if (!r) die(what, r.error());
    return std::move(*r);
}
void must(Result<void> r, const std::string& what) {
    if (!r) die(what, r.error());
}

Value doubles(std::size_t n) {
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) v[i] = double(i) * 0.5;
    return Value(NumericArray::from<double>(std::span<const double>(v)));
}

/// Times `count` calls of `fn` (after `warmup` untimed ones) and emits a latency row.
template <class Fn>
void timed(const std::string& op, std::size_t count, double bytes_per_op, Fn fn, std::size_t warmup = 50) {
    for (std::size_t i = 0; i < warmup; ++i) fn();
    std::vector<double> samples;
    samples.reserve(count);
    const auto cpu0 = CpuSnapshot::now();
    const auto t0 = clock_type::now();
    for (std::size_t i = 0; i < count; ++i) {
        const auto a = clock_type::now();
        fn();
        samples.push_back(elapsed_us(a, clock_type::now()));
    }
    const auto wall = elapsed_us(t0, clock_type::now());
    emit(latency_row(op, samples, wall, bytes_per_op, cpu0, CpuSnapshot::now()));
}

/// Nop() chained through the async layer: each completion (on the strand) starts the next call.
void nop_async(client::ObjectProxy root, std::size_t count) {
    struct Chain {
        std::mutex m;
        std::condition_variable cv;
        bool done = false;
        std::optional<RRError> error;
        std::vector<double> samples;
        clock_type::time_point started;
        std::size_t left = 0;
    };
    auto chain = std::make_shared<Chain>();
    chain->samples.reserve(count);
    chain->left = count;
    std::function<void()> next;
    next = [chain, root, &next] {
        chain->started = clock_type::now();
        root.async_call("Nop", {}, [chain, &next](Result<Value> r) {
            const auto now = clock_type::now();
            if (!r) chain->error = r.error();
            chain->samples.push_back(elapsed_us(chain->started, now));
            if (r && --chain->left > 0) return next();
            std::lock_guard lock(chain->m);
            chain->done = true;
            chain->cv.notify_all();
        });
    };
    const auto cpu0 = CpuSnapshot::now();
    const auto t0 = clock_type::now();
    next();
    std::unique_lock lock(chain->m);
    chain->cv.wait(lock, [&] { return chain->done; });
    const auto wall = elapsed_us(t0, clock_type::now());
    if (chain->error) die("nop_async", *chain->error);
    emit(latency_row("nop_async", chain->samples, wall, 0, cpu0, CpuSnapshot::now()));
}

/// Collects Ticks values (sequence >= 0) arriving on `wire`: one-way latency from the service's stamp.
struct TickSink {
    std::mutex m;
    std::condition_variable cv;
    std::vector<double> latency_us;
    double last_seq = -1;
    clock_type::time_point first, last;

    void attach(client::WireConnection& wire) {
        wire.set_value_handler([this](const WireValue& v) {
            const double now = rr::bench::wall_clock_us();
            const auto* a = v.value.get_if<NumericArray>();
            if (!a || a->size() < 2) return;
            const auto items = a->view<double>();
            if (items[1] < 0) return;
            std::lock_guard lock(m);
            if (latency_us.empty()) first = clock_type::now();
            last = clock_type::now();
            latency_us.push_back(now - items[0]);
            last_seq = items[1];
            cv.notify_all();
        });
    }
    void reset() {
        std::lock_guard lock(m);
        latency_us.clear();
        last_seq = -1;
    }
    /// Waits until the value with sequence `seq` arrived, or `timeout`.
    bool wait_seq(double seq, std::chrono::milliseconds timeout) {
        std::unique_lock lock(m);
        return cv.wait_for(lock, timeout, [&] { return last_seq >= seq; });
    }
};

void wire_latency(client::ObjectProxy root, std::size_t count, double rate_hz) {
    auto wire = must(root.wire_connect("Ticks"), "wire_connect Ticks");
    TickSink sink;
    sink.attach(wire);
    const auto cpu0 = CpuSnapshot::now();
    const auto t0 = clock_type::now();
    must(root.call("StartTicks", {Value::scalar<double>(rate_hz), Value::scalar<std::int32_t>(std::int32_t(count)),
                                  Value::scalar<std::int32_t>(2)}),
         "StartTicks");
    const bool all = sink.wait_seq(double(count - 1), std::chrono::milliseconds(static_cast<long>(count * 1000 / rate_hz) + 10000));
    const auto wall = elapsed_us(t0, clock_type::now());
    wire.set_value_handler(nullptr);
    (void)wire.close();
    std::lock_guard lock(sink.m);
    auto row = latency_row("wire", sink.latency_us, wall, 0, cpu0, CpuSnapshot::now());
    row["rate_hz"] = rate_hz;
    row["sent"] = count;
    row["complete"] = all;
    emit(row);
}

void wire_rate(client::ObjectProxy root, std::size_t count) {
    auto wire = must(root.wire_connect("Ticks"), "wire_connect Ticks");
    TickSink sink;
    sink.attach(wire);
    const auto t0 = clock_type::now();
    must(root.call("StartTicks", {Value::scalar<double>(0), Value::scalar<std::int32_t>(std::int32_t(count)),
                                  Value::scalar<std::int32_t>(2)}),
         "StartTicks");
    const bool all = sink.wait_seq(double(count - 1), 30s);
    wire.set_value_handler(nullptr);
    (void)wire.close();
    std::lock_guard lock(sink.m);
    // Rates over the same window (StartTicks called .. last value in): the service's sending rate, and
    // the distinct values that reached the client (a wire keeps only the newest value, so the
    // difference is coalesced, not lost).
    const double window = elapsed_us(t0, sink.last);
    emit({{"op", "wire_rate"},
          {"sent", count},
          {"delivered", sink.latency_us.size()},
          {"complete", all},
          {"sent_per_s", window > 0 ? double(count) * 1e6 / window : 0.0},
          {"ops_per_s", window > 0 ? double(sink.latency_us.size()) * 1e6 / window : 0.0},
          {"p50_us", rr::bench::percentile(sink.latency_us, 0.5)},
          {"p99_us", rr::bench::percentile(sink.latency_us, 0.99)}});
}

void pipe_rate(client::ObjectProxy root, std::size_t count) {
    auto ep = must(root.pipe_connect("Packets"), "pipe_connect Packets");
    must(ep.set_request_ack(true), "set_request_ack");
    const Value packet = doubles(8);
    const auto cpu0 = CpuSnapshot::now();
    const auto t0 = clock_type::now();
    for (std::size_t i = 0; i < count; ++i) must(ep.send(packet), "pipe send");
    must(ep.wait_acks(count, 60s), "pipe acks");
    const auto wall = elapsed_us(t0, clock_type::now());
    const auto cpu1 = CpuSnapshot::now();
    (void)ep.close();
    emit({{"op", "pipe"},
          {"n", count},
          {"ops_per_s", double(count) * 1e6 / wall},
          {"mb_s", double(count) * 64 / wall},
          {"client_cpu_us_per_op", (cpu1.cpu_us - cpu0.cpu_us) / double(count)}});
}

void memory_rates(client::ObjectProxy root, int repeats) {
    const auto length = must(root.memory_length("Buffer"), "memory_length");
    const double bytes = double(length) * 8;
    Value data = doubles(length);
    for (const char* op : {"memory_read", "memory_write"}) {
        std::vector<double> samples;
        const auto cpu0 = CpuSnapshot::now();
        const auto t0 = clock_type::now();
        for (int i = 0; i < repeats; ++i) {
            const auto a = clock_type::now();
            if (op[7] == 'r') must(root.memory_read("Buffer", 0, length), "memory_read");
            else must(root.memory_write("Buffer", 0, data), "memory_write");
            samples.push_back(elapsed_us(a, clock_type::now()));
        }
        auto row = latency_row(op, samples, elapsed_us(t0, clock_type::now()), bytes, cpu0, CpuSnapshot::now());
        row["bytes"] = bytes;
        emit(row);
    }
}

}  // namespace

int main(int argc, char** argv) {
    std::string url, ops = "nop,nop_async,echo10,echo1000,echo100000,get,set,peek,wire,wire_rate,pipe,memory";
    std::size_t count = 5000;
    bool caller_io = false;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (i + 1 >= argc) {
            std::cerr << "usage: " << argv[0] << " --url URL [--label L] [--count N] [--ops a,b,...]\n";
            return 2;
        }
        std::string v = argv[++i];
        if (a == "--url") url = v;
        else if (a == "--label") g_label = v;
        else if (a == "--count") count = std::stoul(v);
        else if (a == "--ops") ops = v;
        else if (a == "--caller-io") caller_io = v == "1";
        else {
            std::cerr << "unknown option " << a << "\n";
            return 2;
        }
    }
    client::IoThreads io(caller_io ? 0 : 1);
    client::ClientOptions options;
    options.memory_max_transfer_size = 102400;
    options.caller_runs_io = caller_io;
    auto c = must(client::Client::connect(io.executor(), url, options), "connect " + url);
    auto root = c->root();

    std::stringstream list(ops);
    for (std::string op; std::getline(list, op, ',');) {
        const bool blocking = op == "nop" || op.rfind("echo", 0) == 0 || op == "get" || op == "set" || op == "peek";
        if (caller_io && !blocking) {
            std::cerr << "--caller-io runs blocking ops only, not " << op << "\n";
            return 2;
        }
        if (op == "nop") timed("nop", count, 0, [&] { must(root.call("Nop"), "Nop"); });
        else if (op == "nop_async") nop_async(root, count);
        else if (op.rfind("echo", 0) == 0) {
            const std::size_t n = std::stoul(op.substr(4));
            const std::size_t calls = n >= 100000 ? std::max<std::size_t>(20, count / 50) : n >= 1000 ? count / 2 : count;
            const Value arg = doubles(n);
            timed(op, calls, double(n) * 16, [&] {
                auto r = must(root.call("Echo", {arg}), "Echo");
                const auto* a = r.get_if<NumericArray>();
                if (!a || a->size() != n) die("Echo", RRError{MessageErrorType::DataTypeError, "", "wrong echo size", "", nullptr});
            }, n >= 100000 ? 5 : 50);
        } else if (op == "get") timed("get", count, 0, [&] { must(root.get("Value"), "get Value"); });
        else if (op == "set") timed("set", count, 0, [&] { must(root.set("Value", Value::scalar<double>(1.5)), "set Value"); });
        else if (op == "peek") timed("peek", count, 0, [&] { must(root.peek_in_value("Ticks"), "PeekInValue Ticks"); });
        else if (op == "wire") wire_latency(root, std::max<std::size_t>(100, count / 5), 500);
        else if (op == "wire_rate") wire_rate(root, count * 4);
        else if (op == "pipe") pipe_rate(root, count * 2);
        else if (op == "memory") memory_rates(root, 3);
        else {
            std::cerr << "unknown op " << op << "\n";
            return 2;
        }
    }
    (void)c->close_wait();
    return 0;
}
