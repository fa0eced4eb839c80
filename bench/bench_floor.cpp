// rr_bench_floor: the socket floor every RR figure is compared with. Two processes (fork) play
// ping-pong over loopback with blocking Asio sockets: no protocol, no threads, no copies beyond the
// kernel's. Prints one JSON line per row (bench_common.hpp: latency_row).
//
// Usage: rr_bench_floor [--count N] [--label L]
// Rows:
//   tcp_64      64-byte ping-pong over TCP (TCP_NODELAY), N round trips
//   unix_64     64-byte ping-pong over a Unix stream socket, N round trips
//   tcp_bulk    800,000 bytes each way per round trip over TCP (the size of Echo with 100,000 doubles),
//               N/50 round trips (at least 20): the loopback bandwidth reference (mb_s, both directions)
#include <csignal>
#include <cstdio>
#include <iostream>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/connect_pair.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/read.hpp>
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

}  // namespace

int main(int argc, char** argv) {
    std::size_t count = 5000;
    std::string label = "floor";
    for (int i = 1; i + 1 < argc; i += 2) {
        std::string a = argv[i];
        if (a == "--count") count = std::stoul(argv[i + 1]);
        else if (a == "--label") label = argv[i + 1];
    }
    for (auto row : {tcp_row("tcp_64", 64, count), unix_row("unix_64", 64, count),
                     tcp_row("tcp_bulk", 800000, std::max<std::size_t>(20, count / 50))}) {
        row["label"] = label;
        std::cout << row.dump() << std::endl;
    }
    return 0;
}
