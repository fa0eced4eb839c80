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
//               what the kernel alone charges the sender, with no protocol on top; and the latency from
//               the write to the read (p50/p99/max µs), delivered messages/s.
#include <csignal>
#include <cstdio>
#include <cstring>
#include <functional>
#include <iostream>
#include <string>
#include <thread>

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

nlohmann::json fanout_floor_row(std::size_t clients, double seconds, double hz, std::size_t bytes) {
    rr::bench::raise_fd_limit();
    bytes = std::max<std::size_t>(bytes, sizeof(std::int64_t));
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
    auto now_ns = [] { return std::chrono::duration_cast<std::chrono::nanoseconds>(clock_type::now().time_since_epoch()).count(); };

    // Reader: every socket always has one read of a whole message pending.
    std::vector<std::vector<char>> buffers(clients, std::vector<char>(bytes));
    std::vector<double> latency_us;
    const auto ticks = static_cast<std::size_t>(seconds * hz);
    latency_us.reserve(ticks * clients);
    std::function<void(std::size_t)> arm = [&](std::size_t i) {
        asio::async_read(readers[i], asio::buffer(buffers[i]), [&, i](boost::system::error_code ec, std::size_t) {
            if (ec) return;  // EOF: the writer is done
            std::int64_t stamp = 0;
            std::memcpy(&stamp, buffers[i].data(), sizeof stamp);
            latency_us.push_back(double(now_ns() - stamp) / 1000.0);
            arm(i);
        });
    };
    for (std::size_t i = 0; i < clients; ++i) arm(i);

    rr::bench::CpuSnapshot writer_before, writer_after;
    double writer_wall_us = 0;
    std::thread writer([&] {
        std::vector<char> message(bytes, 'x');
        const auto period = std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(1.0 / hz));
        writer_before = rr::bench::CpuSnapshot::now(RUSAGE_THREAD);
        const auto start = clock_type::now();
        for (std::size_t t = 0; t < ticks; ++t) {
            std::this_thread::sleep_until(start + t * period);
            for (auto& w : writers) {
                const std::int64_t stamp = now_ns();
                std::memcpy(message.data(), &stamp, sizeof stamp);
                asio::write(w, asio::buffer(message));
            }
        }
        writer_wall_us = rr::bench::elapsed_us(start, clock_type::now());
        writer_after = rr::bench::CpuSnapshot::now(RUSAGE_THREAD);
        for (auto& w : writers) w.shutdown(tcp::socket::shutdown_send);
    });
    const auto reader_before = rr::bench::CpuSnapshot::now(RUSAGE_THREAD);
    io.run();
    const auto reader_after = rr::bench::CpuSnapshot::now(RUSAGE_THREAD);
    writer.join();

    const double sent = double(ticks * clients);
    const double delivered = double(latency_us.size());
    return {{"op", "fanout_floor"},
            {"clients", clients},
            {"hz", hz},
            {"bytes", bytes},
            {"seconds", seconds},
            {"sent", sent},
            {"delivered", delivered},
            {"delivered_per_s", writer_wall_us > 0 ? delivered * 1e6 / writer_wall_us : 0.0},
            {"p50_us", rr::bench::percentile(latency_us, 0.50)},
            {"p99_us", rr::bench::percentile(latency_us, 0.99)},
            {"max_us", latency_us.empty() ? 0.0 : *std::max_element(latency_us.begin(), latency_us.end())},
            {"writer_cpu_pct", writer_wall_us > 0 ? 100 * (writer_after.cpu_us - writer_before.cpu_us) / writer_wall_us : 0.0},
            {"writer_cpu_us_per_value", sent > 0 ? (writer_after.cpu_us - writer_before.cpu_us) / sent : 0.0},
            {"writer_vcsw_per_value", sent > 0 ? double(writer_after.vcsw - writer_before.vcsw) / sent : 0.0},
            {"reader_cpu_us_per_value", delivered > 0 ? (reader_after.cpu_us - reader_before.cpu_us) / delivered : 0.0}};
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
