// libFuzzer target for the JSON WebSocket API (server/gateway/json_socket.cpp, docs/json-api.md): the
// messages of one socket go through the real subprotocol handler of a running gateway with its demo
// devices (gateway_harness.hpp), so requests reach the JSON API, the value conversions and the
// devices. Only the WebSocket framing is left out (fuzz_gateway_port covers it).
//
// Input: up to 8 text messages, one per line. The contract checked: every message is answered exactly
// once, within 20 s, by a JSON object {"id", "result"} or {"id", "error": {"name", "message"}} (id
// null when the message had no usable id); everything the gateway sends is a JSON object.
// Seeds: test/fuzz/seeds/fuzz_json_socket (the examples of docs/json-api.md).
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "server/gateway/binary_push.hpp"
#include "server/gateway/json_socket.hpp"
#include "test/fuzz/gateway_harness.hpp"

namespace {

using namespace std::chrono_literals;

class FakeSocket : public rr::server::http::JsonSocket {
public:
    void send(std::string text) override { take(std::move(text)); }
    void send_urgent(std::string text) override { take(std::move(text)); }
    void send_binary(std::string bytes) override {
        auto j = rr::server::gateway::decode_binary_push(bytes);
        if (!j) rr::fuzz::fail_input("the gateway sent a binary message that is not a binary push: " + j.error().message);
        take(j->dump());
    }
    void close() override {
        std::lock_guard lock(mutex_);
        closed_by_server_ = true;
    }
    std::string peer() const override { return "fuzz"; }

    /// Waits until `n` replies (messages with an "id") arrived; false on timeout.
    bool wait_replies(std::size_t n, std::chrono::milliseconds timeout) {
        std::unique_lock lock(mutex_);
        return cv_.wait_for(lock, timeout, [&] { return replies_ >= n; });
    }
    std::size_t replies() {
        std::lock_guard lock(mutex_);
        return replies_;
    }

private:
    void take(std::string text) {
        auto j = nlohmann::json::parse(text, nullptr, false);
        if (j.is_discarded() || !j.is_object()) rr::fuzz::fail_input("the gateway sent a message that is not a JSON object: " + text);
        if (j.contains("id")) {
            const auto& id = j["id"];
            if (!id.is_null() && !id.is_number_integer() && !id.is_string())
                rr::fuzz::fail_input("a reply with an id that is not null, an integer or a string: " + text);
            const bool result = j.contains("result"), error = j.contains("error");
            if (result == error) rr::fuzz::fail_input("a reply needs exactly one of result and error: " + text);
            if (error) {
                const auto& e = j["error"];
                if (!e.is_object() || !e.contains("name") || !e["name"].is_string() || !e.contains("message") ||
                    !e["message"].is_string())
                    rr::fuzz::fail_input("an error reply without name and message: " + text);
            }
            std::lock_guard lock(mutex_);
            ++replies_;
            cv_.notify_all();
        }
    }

    std::mutex mutex_;
    std::condition_variable cv_;
    std::size_t replies_ = 0;
    bool closed_by_server_ = false;
};

const rr::server::http::JsonSocketHandler& handler() {
    static const rr::server::http::JsonSocketHandler* h = [] {
        const auto* found = rr::fuzz::gateway().http->find_subprotocol(rr::server::gateway::kJsonSubprotocol);
        if (!found) rr::fuzz::fail_input("the JSON subprotocol is not installed");
        return found;
    }();
    return *h;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > 256 * 1024) return 0;
    const auto& h = handler();
    std::vector<std::string> messages;
    std::string_view rest(reinterpret_cast<const char*>(data), size);
    while (!rest.empty() && messages.size() < 8) {
        auto nl = rest.find('\n');
        messages.emplace_back(rest.substr(0, nl));
        rest = nl == std::string_view::npos ? std::string_view{} : rest.substr(nl + 1);
    }
    auto socket = std::make_shared<FakeSocket>();
    if (h.on_open) h.on_open(socket);
    for (auto& m : messages) h.on_message(socket, std::move(m));
    if (!socket->wait_replies(messages.size(), 20s))
        rr::fuzz::fail_input("only " + std::to_string(socket->replies()) + " of " + std::to_string(messages.size()) +
                             " messages were answered within 20 s");
    if (h.on_close) h.on_close(socket);
    // A webcam left streaming would make frames for every later input: stop both (state kept small).
    if (std::string_view(reinterpret_cast<const char*>(data), size).find("StartStreaming") != std::string_view::npos) {
        auto cleanup = std::make_shared<FakeSocket>();
        if (h.on_open) h.on_open(cleanup);
        for (const char* m : {R"({"id":1,"op":"call","device":"webcam","object":"Webcams[0]","member":"StopStreaming"})",
                              R"({"id":2,"op":"call","device":"webcam","object":"Webcams[1]","member":"StopStreaming"})"})
            h.on_message(cleanup, m);
        cleanup->wait_replies(2, 20s);
        if (h.on_close) h.on_close(cleanup);
    }
    return 0;
}
