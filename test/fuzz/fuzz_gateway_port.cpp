// libFuzzer target for everything behind the gateway's one TCP port: the first-bytes detection
// (server/transport/tcp_listener.cpp: `RRAC` → RR stream, anything else → HTTP), the RR stream
// protocol and server connection (CreateConnection, heartbeats, requests), Beast's HTTP request
// parsing and the HttpServer's handling of it (server/http/http_server.cpp: origins, routes, static
// files, WebSocket upgrades with their subprotocols, then WebSocket frames to the raw RR or the JSON
// API session). The bytes go over a real loopback connection to a running gateway with its demo
// devices (gateway_harness.hpp), as a stranger's would.
//
// Input: the bytes a client sends. The harness sends them, closes its sending side, and reads until
// the gateway closes the connection. The contract checked: the gateway closes a connection whose peer
// has finished sending (within 20 s: no connection lingers after its peer went away), and never
// answers with a file from outside its web root (the canary of gateway_harness.hpp).
// Seeds: test/fuzz/seeds/fuzz_gateway_port (HTTP requests, WebSocket upgrades with frames, RR
// streams from the protocol tests).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "test/fuzz/gateway_harness.hpp"

namespace {

using rr::fuzz::fail_input;
using Clock = std::chrono::steady_clock;

/// True when `input`, %-decoded and lower-cased, contains "canary" (so an echo of it may hold kCanary).
bool spells_canary(std::string_view input) {
    std::string plain;
    plain.reserve(input.size());
    auto hex = [](char c) -> int {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return -1;
    };
    for (std::size_t i = 0; i < input.size(); ++i) {
        char c = input[i];
        if (c == '%' && i + 2 < input.size() && hex(input[i + 1]) >= 0 && hex(input[i + 2]) >= 0) {
            c = static_cast<char>(hex(input[i + 1]) * 16 + hex(input[i + 2]));
            i += 2;
        }
        plain.push_back((c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c);
    }
    return plain.find("canary") != std::string::npos;
}

class Fd {
public:
    explicit Fd(int fd) : fd_(fd) {}
    ~Fd() {
        if (fd_ >= 0) ::close(fd_);
    }
    int get() const { return fd_; }

private:
    int fd_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace std::chrono_literals;
    if (size > 1u << 20) return 0;
    const auto& g = rr::fuzz::gateway();
    Fd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
    if (fd.get() < 0) fail_input("socket(): " + std::to_string(errno));
    // Reset instead of TIME_WAIT on close: thousands of connections per second would use up the ports.
    linger lg{1, 0};
    ::setsockopt(fd.get(), SOL_SOCKET, SO_LINGER, &lg, sizeof lg);
    int one = 1;
    ::setsockopt(fd.get(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(g.port);
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd.get(), reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        // Interrupted by a signal (libFuzzer's timer sends SIGALRM each second): the connection goes on
        // in the kernel; wait for it to finish and take its result. (A harness false alarm, seen in a
        // long run.)
        if (errno != EINTR) fail_input("connect(): " + std::to_string(errno));
        pollfd w{fd.get(), POLLOUT, 0};
        int r = 0;
        do r = ::poll(&w, 1, 5000);
        while (r < 0 && errno == EINTR);
        int err = 0;
        socklen_t len = sizeof err;
        if (r <= 0 || ::getsockopt(fd.get(), SOL_SOCKET, SO_ERROR, &err, &len) != 0 || err != 0)
            fail_input("connect() after EINTR: " + std::to_string(r <= 0 ? errno : err));
    }

    // Send everything (reading meanwhile, so a gateway that answers early never blocks us), then close
    // the sending side and read until the gateway closes.
    std::string received;
    std::size_t sent = 0;
    bool write_closed = false;
    const auto deadline = Clock::now() + 20s;
    char buf[16384];
    while (true) {
        if (sent == size && !write_closed) {
            ::shutdown(fd.get(), SHUT_WR);
            write_closed = true;
        }
        pollfd p{fd.get(), static_cast<short>(POLLIN | (write_closed ? 0 : POLLOUT)), 0};
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
        if (left <= 0) fail_input("the gateway kept a connection open 20 s after its peer finished sending");
        if (::poll(&p, 1, static_cast<int>(left)) < 0 && errno != EINTR) fail_input("poll(): " + std::to_string(errno));
        if (p.revents & (POLLIN | POLLHUP | POLLERR)) {
            const auto n = ::recv(fd.get(), buf, sizeof buf, 0);
            if (n == 0) break;                             // closed by the gateway
            if (n < 0 && errno == ECONNRESET) break;       // reset by the gateway: closed as well
            if (n < 0 && errno != EAGAIN && errno != EINTR) break;
            if (n > 0 && received.size() < (1u << 20)) received.append(buf, static_cast<std::size_t>(n));
        }
        if (!write_closed && (p.revents & POLLOUT)) {
            const auto n = ::send(fd.get(), data + sent, size - sent, MSG_NOSIGNAL);
            if (n > 0) sent += static_cast<std::size_t>(n);
            else if (n < 0 && errno != EAGAIN && errno != EINTR) write_closed = true;  // the gateway closed first
        }
    }
    // The gateway echoes parts of a request in its error answers, and libFuzzer learns the canary from
    // the comparison below: only an input that does not spell it (as text or %-encoded) proves a leak.
    if (received.find(rr::fuzz::kCanary) != std::string::npos && !spells_canary({reinterpret_cast<const char*>(data), size}))
        fail_input("the gateway served a file from outside its web root");
    return 0;
}
