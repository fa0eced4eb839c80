// Test helper: a client-role StreamConnection over a blocking socket of any stream protocol (TCP, Unix,
// …): CreateConnection only, no client session, so tests can send special requests and raw bytes at
// will and watch how a listener treats a misbehaving peer (peer_limits_test.cpp and the per-transport
// copies of its cases).
#pragma once

#include <array>
#include <chrono>
#include <optional>
#include <span>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/write.hpp>
#include <catch2/catch.hpp>

#include "core/session/elements.hpp"
#include "core/session/stream_connection.hpp"

namespace rr::server::testing {

/// `size` zero bytes behind a 4-byte magic and a little-endian MessageSize of `size` (< 256).
inline std::vector<std::byte> framed(const char* magic, std::uint8_t size) {
    std::vector<std::byte> bytes(size, std::byte{0});
    for (int i = 0; i < 4; ++i) bytes[i] = static_cast<std::byte>(magic[i]);
    bytes[4] = std::byte{size};
    return bytes;
}

inline bool is_closed_event(const std::optional<StreamEvent>& e) { return e && std::holds_alternative<StreamClosed>(*e); }

inline const MessageEntry* reply_entry(const std::optional<StreamEvent>& e) {
    if (!e) return nullptr;
    auto* m = std::get_if<StreamMessage>(&*e);
    return m && !m->message.entries.empty() ? &m->message.entries.front() : nullptr;
}

template <class Protocol>
struct RawStream {
    boost::asio::io_context io;
    typename Protocol::socket socket{io};
    StreamConnection conn;
    NodeID remote;

    /// Connects to `endpoint`; with `handshake`, waits for CreateConnection to complete (30 s at most: a bound on a hang).
    RawStream(const typename Protocol::endpoint& endpoint, StreamConfig config, bool handshake = true)
        : conn(StreamRole::client, with_id(std::move(config)), std::chrono::steady_clock::now()) {
        socket.connect(endpoint);
        socket.non_blocking(true);
        if (!handshake) return;
        auto e = next_event(std::chrono::seconds(30));
        REQUIRE(e);
        auto* c = std::get_if<StreamConnected>(&*e);
        REQUIRE(c);
        remote = c->remote_node_id;
    }

    static StreamConfig with_id(StreamConfig c) {
        c.local_node_id = *NodeID::parse("12345678-2222-3333-4444-555555555555");
        return c;
    }

    void write_raw(const std::vector<std::byte>& bytes) {
        socket.non_blocking(false);
        boost::system::error_code ec;
        boost::asio::write(socket, boost::asio::buffer(bytes), ec);
        socket.non_blocking(true);
    }

    void flush() {
        auto out = conn.pending_output();
        if (out.empty()) return;
        socket.non_blocking(false);
        boost::system::error_code ec;
        boost::asio::write(socket, boost::asio::buffer(out.data(), out.size()), ec);
        conn.consume_output(out.size());
        socket.non_blocking(true);
    }

    /// The next event, a StreamClosed when the peer closed the socket, or nullopt after `timeout`.
    std::optional<StreamEvent> next_event(std::chrono::milliseconds timeout) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        std::array<std::byte, 65536> buf;
        while (std::chrono::steady_clock::now() < deadline) {
            if (auto e = conn.poll_event()) return e;
            flush();
            boost::system::error_code ec;
            auto n = socket.read_some(boost::asio::buffer(buf), ec);
            if (ec == boost::asio::error::would_block) {
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
                continue;
            }
            if (ec) return StreamEvent{StreamClosed{make_error(MessageErrorType::ConnectionError, ec.message())}};
            (void)conn.feed(std::span<const std::byte>(buf.data(), n), std::chrono::steady_clock::now());
        }
        return std::nullopt;
    }

    /// True once the peer closed the socket (EOF / reset) within `timeout`; bytes it sends are dropped.
    bool closed_by_peer(std::chrono::milliseconds timeout) {
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        std::array<std::byte, 4096> buf;
        while (std::chrono::steady_clock::now() < deadline) {
            boost::system::error_code ec;
            socket.read_some(boost::asio::buffer(buf), ec);
            if (ec == boost::asio::error::would_block) {
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
                continue;
            }
            if (ec) return true;
        }
        return false;
    }

    /// Sends a special request (no client session) whose entry carries `padding` extra bytes.
    void send_special(MessageEntryType type, std::string path, std::size_t padding) {
        Message m;
        m.header.sender_node_id = with_id({}).local_node_id;
        m.header.receiver_node_id = remote;
        MessageEntry e;
        e.entry_type = type;
        e.service_path = std::move(path);
        std::vector<std::uint8_t> pad(padding, 0x5a);
        e.elements.push_back(make_array_element("padding", std::span<const std::uint8_t>(pad)));
        m.entries.push_back(std::move(e));
        REQUIRE(conn.send(m, std::chrono::steady_clock::now()));
    }
};

}  // namespace rr::server::testing
