// rr_bench_floor: the socket floor every RR figure is compared with. Two processes (fork) play
// ping-pong over loopback with blocking Asio sockets: no protocol, no threads, no copies beyond the
// kernel's. Prints one JSON line per row (bench_common.hpp: latency_row).
//
// Usage: rr_bench_floor [--count N] [--label L]
//        rr_bench_floor --fanout N [--seconds S] [--hz H] [--bytes B] [--label L]
// Rows:
//   tcp_64      64-byte ping-pong over TCP (TCP_NODELAY), N round trips
//   unix_64     64-byte ping-pong over a Unix stream socket, N round trips
//   tcp_bulk    800,000 bytes each way per round trip over TCP (the size of Echo with 100,000 doubles),
//               N/50 round trips (at least 20): the loopback bandwidth reference (mb_s, both directions)
//   fanout_floor  (--fanout N only) the floor of the gateway's fan-out rows: one thread writes a B-byte
//               message (default 128) to each of N loopback TCP sockets H times a second (default 100)
//               for S seconds (default 5), one blocking write per message as the gateway makes one
//               WebSocket write per value and client; another thread reads them all (one io_context).
//               Reports the writer's CPU µs and context switches per message (its thread's getrusage):
//               what the kernel alone charges the sender, with no protocol on top; the latency from
//               the write to the read (p50/p99/max µs), delivered messages/s; and the latency from the
//               tick (p50_tick_us/p99_tick_us/max_tick_us: one stamp per tick, taken before its first
//               write, as a device value is stamped once and then fanned out), which includes the time
//               the writer takes to reach the socket, as the gateway's fan-out rows do. When one process may not
//               hold 2N sockets (RLIMIT_NOFILE: 10,000 clients under a 20,000 limit), the reader runs in a
//               forked child with its N sockets and sends its figures back through a pipe ("split": true).
#include <csignal>
#include <cstdio>
#include <cstring>
#include <functional>
#include <algorithm>
#include <iostream>
#include <stdexcept>
#include <string>
#include <thread>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/connect_pair.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/socket_base.hpp>
#include <boost/asio/write.hpp>

#include "bench/bench_common.hpp"

namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using unix_stream = asio::local::stream_protocol;
using clock_type = std::chrono::steady_clock;

namespace {

/// Child side: answers each message of `size` bytes with the same bytes until EOF.
template <class Socket>
void echo_loop(Socket& s, std::size_t size) {
    std::vector<char> buf(size);
    boost::system::error_code ec;
    for (;;) {
        asio::read(s, asio::buffer(buf), ec);
        if (ec) return;
        asio::write(s, asio::buffer(buf), ec);
        if (ec) return;
    }
}

/// Parent side: `count` timed round trips of `size` bytes after 100 untimed ones.
template <class Socket>
nlohmann::json ping(Socket& s, const std::string& op, std::size_t size, std::size_t count) {
    std::vector<char> out(size, 'x'), in(size);
    auto round_trip = [&] {
        asio::write(s, asio::buffer(out));
        asio::read(s, asio::buffer(in));
    };
    for (int i = 0; i < 100 && size < 4096; ++i) round_trip();
    std::vector<double> samples;
    samples.reserve(count);
    const auto cpu0 = rr::bench::CpuSnapshot::now();
    const auto t0 = clock_type::now();
    for (std::size_t i = 0; i < count; ++i) {
        const auto a = clock_type::now();
        round_trip();
        samples.push_back(rr::bench::elapsed_us(a, clock_type::now()));
    }
    const auto wall = rr::bench::elapsed_us(t0, clock_type::now());
    return rr::bench::latency_row(op, samples, wall, size > 64 ? 2.0 * double(size) : 0, cpu0, rr::bench::CpuSnapshot::now());
}

nlohmann::json tcp_row(const std::string& op, std::size_t size, std::size_t count) {
    asio::io_context io;
    tcp::acceptor acceptor(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    const auto endpoint = acceptor.local_endpoint();
    std::fflush(stdout);
    const pid_t child = fork();
    if (child == 0) {
        asio::io_context child_io;
        tcp::socket s(child_io);
        s.connect(endpoint);
        s.set_option(tcp::no_delay(true));
        echo_loop(s, size);
        _exit(0);
    }
    tcp::socket s = acceptor.accept();
    s.set_option(tcp::no_delay(true));
    auto row = ping(s, op, size, count);
    s.close();
    waitpid(child, nullptr, 0);
    return row;
}

nlohmann::json unix_row(const std::string& op, std::size_t size, std::size_t count) {
    asio::io_context io;
    unix_stream::socket a(io), b(io);
    asio::local::connect_pair(a, b);
    std::fflush(stdout);
    const pid_t child = fork();
    if (child == 0) {
        a.close();
        echo_loop(b, size);
        _exit(0);
    }
    b.close();
    auto row = ping(a, op, size, count);
    a.close();
    waitpid(child, nullptr, 0);
    return row;
}

std::int64_t now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(clock_type::now().time_since_epoch()).count();
}

/// One blocking write of a `bytes`-byte message (its first 8 bytes the clock in ns at the write, the
/// next 8 the clock at the tick's start) to every socket, `hz` times a second for `seconds`; the writer's CPU per message and its wall time.
struct WriterFigures {
    rr::bench::CpuSnapshot before, after;
    double wall_us = 0;
};
WriterFigures write_ticks(std::vector<tcp::socket>& writers, double seconds, double hz, std::size_t bytes) {
    WriterFigures f;
    std::vector<char> message(bytes, 'x');
    const auto ticks = static_cast<std::size_t>(seconds * hz);
    const auto period = std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(1.0 / hz));
    f.before = rr::bench::CpuSnapshot::now(RUSAGE_THREAD);
    const auto start = clock_type::now();
    for (std::size_t t = 0; t < ticks; ++t) {
        std::this_thread::sleep_until(start + t * period);
        const std::int64_t tick = now_ns();
        std::memcpy(message.data() + sizeof tick, &tick, sizeof tick);
        for (auto& w : writers) {
            const std::int64_t stamp = now_ns();
            std::memcpy(message.data(), &stamp, sizeof stamp);
            asio::write(w, asio::buffer(message));
        }
    }
    f.wall_us = rr::bench::elapsed_us(start, clock_type::now());
    f.after = rr::bench::CpuSnapshot::now(RUSAGE_THREAD);
    for (auto& w : writers) w.shutdown(tcp::socket::shutdown_send);
    return f;
}

/// Each message's latency (µs) from its write and from its tick.
struct Latencies {
    std::vector<double> write_us, tick_us;
};

/// Reads whole messages from every socket until EOF on all; the latencies of each, sorted.
Latencies read_all(asio::io_context& io, std::vector<tcp::socket>& readers, std::size_t bytes, std::size_t expected) {
    std::vector<std::vector<char>> buffers(readers.size(), std::vector<char>(bytes));
    Latencies latency;
    latency.write_us.reserve(expected);
    latency.tick_us.reserve(expected);
    std::function<void(std::size_t)> arm = [&](std::size_t i) {
        asio::async_read(readers[i], asio::buffer(buffers[i]), [&, i](boost::system::error_code ec, std::size_t) {
            if (ec) return;  // EOF: the writer is done
            std::int64_t stamp = 0, tick = 0;
            std::memcpy(&stamp, buffers[i].data(), sizeof stamp);
            std::memcpy(&tick, buffers[i].data() + sizeof stamp, sizeof tick);
            const std::int64_t now = now_ns();
            latency.write_us.push_back(double(now - stamp) / 1000.0);
            latency.tick_us.push_back(double(now - tick) / 1000.0);
            arm(i);
        });
    };
    for (std::size_t i = 0; i < readers.size(); ++i) arm(i);
    io.run();
    std::sort(latency.write_us.begin(), latency.write_us.end());
    std::sort(latency.tick_us.begin(), latency.tick_us.end());
    return latency;
}

/// p50/p99/max of sorted latencies under `suffix`'s names (p50_us, p50_tick_us, ...).
void put_latencies(nlohmann::json& row, const std::vector<double>& sorted_us, const std::string& suffix) {
    row["p50" + suffix] = rr::bench::percentile(sorted_us, 0.50);
    row["p99" + suffix] = rr::bench::percentile(sorted_us, 0.99);
    row["max" + suffix] = sorted_us.empty() ? 0.0 : sorted_us.back();
}

nlohmann::json floor_row(std::size_t clients, double seconds, double hz, std::size_t bytes, const WriterFigures& w,
                         const Latencies& latency, double reader_cpu_us) {
    const double sent = double(static_cast<std::size_t>(seconds * hz) * clients);
    const double delivered = double(latency.write_us.size());
    nlohmann::json row = {{"op", "fanout_floor"},
            {"clients", clients},
            {"hz", hz},
            {"bytes", bytes},
            {"seconds", seconds},
            {"sent", sent},
            {"delivered", delivered},
            {"delivered_per_s", w.wall_us > 0 ? delivered * 1e6 / w.wall_us : 0.0},
            {"writer_cpu_pct", w.wall_us > 0 ? 100 * (w.after.cpu_us - w.before.cpu_us) / w.wall_us : 0.0},
            {"writer_cpu_us_per_value", sent > 0 ? (w.after.cpu_us - w.before.cpu_us) / sent : 0.0},
            {"writer_vcsw_per_value", sent > 0 ? double(w.after.vcsw - w.before.vcsw) / sent : 0.0},
            {"reader_cpu_us_per_value", delivered > 0 ? reader_cpu_us / delivered : 0.0}};
    put_latencies(row, latency.write_us, "_us");
    put_latencies(row, latency.tick_us, "_tick_us");
    return row;
}

/// The fan-out floor with the reader in a forked child (its own N sockets): for N too large for one
/// process's descriptor limit. The child connects, reads until EOF, and writes its latencies' summary
/// and CPU to a pipe.
nlohmann::json fanout_floor_split(std::size_t clients, double seconds, double hz, std::size_t bytes) {
    asio::io_context io;
    tcp::acceptor acceptor(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    acceptor.listen(asio::socket_base::max_listen_connections);
    const auto endpoint = acceptor.local_endpoint();
    int pipe_fds[2];
    if (::pipe(pipe_fds) != 0) throw std::runtime_error("pipe");
    std::fflush(stdout);
    const pid_t child = fork();
    if (child == 0) {
        ::close(pipe_fds[0]);
        acceptor.close();
        asio::io_context child_io;
        std::vector<tcp::socket> readers;
        readers.reserve(clients);
        for (std::size_t i = 0; i < clients; ++i) readers.emplace_back(child_io).connect(endpoint);
        const auto before = rr::bench::CpuSnapshot::now();
        const auto latency = read_all(child_io, readers, bytes, static_cast<std::size_t>(seconds * hz) * clients);
        const auto after = rr::bench::CpuSnapshot::now();
        nlohmann::json figures = {{"delivered", latency.write_us.size()}, {"reader_cpu_us", after.cpu_us - before.cpu_us}};
        put_latencies(figures, latency.write_us, "_us");
        put_latencies(figures, latency.tick_us, "_tick_us");
        const std::string out = figures.dump();
        (void)!::write(pipe_fds[1], out.data(), out.size());
        ::close(pipe_fds[1]);
        _exit(0);
    }
    ::close(pipe_fds[1]);
    std::vector<tcp::socket> writers;
    writers.reserve(clients);
    for (std::size_t i = 0; i < clients; ++i) {
        writers.push_back(acceptor.accept());
        writers.back().set_option(tcp::no_delay(true));
    }
    const auto w = write_ticks(writers, seconds, hz, bytes);
    std::string text;
    char buf[4096];
    for (ssize_t n; (n = ::read(pipe_fds[0], buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
    ::close(pipe_fds[0]);
    waitpid(child, nullptr, 0);
    writers.clear();
    auto reader = nlohmann::json::parse(text, nullptr, false);
    if (reader.is_discarded()) reader = nlohmann::json::object();
    auto row = floor_row(clients, seconds, hz, bytes, w, {}, 0);
    const double delivered = reader.value("delivered", 0.0);
    row["delivered"] = delivered;
    row["delivered_per_s"] = w.wall_us > 0 ? delivered * 1e6 / w.wall_us : 0.0;
    for (const char* k : {"p50_us", "p99_us", "max_us", "p50_tick_us", "p99_tick_us", "max_tick_us"}) row[k] = reader.value(k, 0.0);
    row["reader_cpu_us_per_value"] = delivered > 0 ? reader.value("reader_cpu_us", 0.0) / delivered : 0.0;
    row["split"] = true;
    return row;
}

nlohmann::json fanout_floor_row(std::size_t clients, double seconds, double hz, std::size_t bytes) {
    rr::bench::raise_fd_limit();
    bytes = std::max<std::size_t>(bytes, 2 * sizeof(std::int64_t));  // the write's and the tick's stamps
    rlimit limit{};
    getrlimit(RLIMIT_NOFILE, &limit);
    if (2 * clients + 64 > limit.rlim_cur) return fanout_floor_split(clients, seconds, hz, bytes);
    asio::io_context io;
    tcp::acceptor acceptor(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    acceptor.listen(asio::socket_base::max_listen_connections);
    std::vector<tcp::socket> readers, writers;
    readers.reserve(clients);
    writers.reserve(clients);
    for (std::size_t i = 0; i < clients; ++i) {
        readers.emplace_back(io).connect(acceptor.local_endpoint());
        writers.push_back(acceptor.accept());
        writers.back().set_option(tcp::no_delay(true));
    }
    WriterFigures w;
    std::thread writer([&] { w = write_ticks(writers, seconds, hz, bytes); });
    const auto reader_before = rr::bench::CpuSnapshot::now(RUSAGE_THREAD);
    const auto latency = read_all(io, readers, bytes, static_cast<std::size_t>(seconds * hz) * clients);
    const auto reader_after = rr::bench::CpuSnapshot::now(RUSAGE_THREAD);
    writer.join();
    return floor_row(clients, seconds, hz, bytes, w, latency, reader_after.cpu_us - reader_before.cpu_us);
}

}  // namespace

int main(int argc, char** argv) {
    std::size_t count = 5000;
    std::string label = "floor";
    std::size_t fanout = 0, bytes = 128;
    double seconds = 5, hz = 100;
    for (int i = 1; i + 1 < argc; i += 2) {
        std::string a = argv[i];
        if (a == "--count") count = std::stoul(argv[i + 1]);
        else if (a == "--label") label = argv[i + 1];
        else if (a == "--fanout") fanout = std::stoul(argv[i + 1]);
        else if (a == "--seconds") seconds = std::stod(argv[i + 1]);
        else if (a == "--hz") hz = std::stod(argv[i + 1]);
        else if (a == "--bytes") bytes = std::stoul(argv[i + 1]);
        else {
            std::cerr << "rr_bench_floor: unknown option " << a << "\n";
            return 2;
        }
    }
    if (fanout > 0) {
        auto row = fanout_floor_row(fanout, seconds, hz, bytes);
        row["label"] = label;
        std::cout << row.dump() << std::endl;
        return 0;
    }
    for (auto row : {tcp_row("tcp_64", 64, count), unix_row("unix_64", 64, count),
                     tcp_row("tcp_bulk", 800000, std::max<std::size_t>(20, count / 50))}) {
        row["label"] = label;
        std::cout << row.dump() << std::endl;
    }
    return 0;
}
