// libFuzzer target for the REST half of the JSON API (server/gateway/json_rest.cpp, docs/json-api.md):
// HTTP requests parsed by Beast exactly as the gateway's HttpServer parses them (same header and body
// limits), then handed to the real route handlers of a running gateway with its demo devices
// (gateway_harness.hpp): /api/devices/..., /livez, /readyz, /metrics. Socket I/O is left out
// (fuzz_gateway_port covers it).
//
// Input: one or more HTTP/1.1 requests back to back (at most 4). The contract checked: every routed
// request is answered exactly once within 20 s; /api answers are JSON (`application/json`), and an
// answer with status 400 or above is {"error": {"name", "message"}}.
// Seeds: test/fuzz/seeds/fuzz_json_rest (the REST examples of docs/json-api.md).
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include <boost/asio/buffer.hpp>
#include <boost/beast/http.hpp>
#include <nlohmann/json.hpp>

#include "test/fuzz/gateway_harness.hpp"

namespace {

using namespace std::chrono_literals;
namespace bhttp = boost::beast::http;
using rr::fuzz::fail_input;
using rr::server::http::Request;
using rr::server::http::Response;

struct Answer {
    std::mutex mutex;
    std::condition_variable cv;
    std::optional<Response> response;
    int count = 0;
};

void check_answer(const Request& req, const Response& r) {
    const std::string_view target(req.target().data(), req.target().size());
    const unsigned status = r.result_int();
    if (status < 100 || status > 599) fail_input("HTTP status " + std::to_string(status));
    if (target.rfind("/api", 0) != 0) return;
    if (r[bhttp::field::content_type] != "application/json")
        fail_input("an /api answer that is not application/json (" + std::to_string(status) + ")");
    auto j = nlohmann::json::parse(r.body(), nullptr, false);
    if (j.is_discarded()) fail_input("an /api answer that is not JSON: " + r.body());
    if (status >= 400) {
        if (!j.is_object() || !j.contains("error") || !j["error"].is_object() || !j["error"].contains("name") ||
            !j["error"].contains("message"))
            fail_input("an /api error answer without {\"error\": {\"name\", \"message\"}}: " + r.body());
    }
}

void serve(const Request& req) {
    const auto& g = rr::fuzz::gateway();
    const auto origin = req[bhttp::field::origin];
    if (!origin.empty() && !rr::server::http::same_origin(origin, req[bhttp::field::host]) &&
        !rr::server::http::origin_allowed(g.http->options().allowed_origins, origin))
        return;  // the HttpServer answers 403 before any route
    const std::string_view target(req.target().data(), req.target().size());
    const auto* route = g.http->find_route(req.method(), target.substr(0, target.find('?')));
    if (!route) return;
    auto answer = std::make_shared<Answer>();
    // No connection to watch: the fuzzer's client never goes away before its answer.
    (*route)(
        req,
        [answer](Response r) {
            std::lock_guard lock(answer->mutex);
            if (++answer->count == 1) answer->response = std::move(r);
            answer->cv.notify_all();
        },
        nullptr);
    std::unique_lock lock(answer->mutex);
    if (!answer->cv.wait_for(lock, 20s, [&] { return answer->count > 0; }))
        fail_input("no answer within 20 s to " + std::string(req.method_string()) + " " + std::string(target));
    check_answer(req, *answer->response);
    // A second answer would be written to the socket after the first: wait a moment for one.
    if (answer->cv.wait_for(lock, 0ms, [&] { return answer->count > 1; })) fail_input("a request was answered twice");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > 2u << 20) return 0;
    (void)rr::fuzz::gateway();
    std::string_view rest(reinterpret_cast<const char*>(data), size);
    for (int n = 0; n < 4 && !rest.empty(); ++n) {
        bhttp::request_parser<bhttp::string_body> parser;  // as HttpSession::read()
        parser.eager(true);
        parser.body_limit(rr::fuzz::gateway().http->options().max_body_bytes);
        parser.header_limit(16 * 1024);
        boost::beast::error_code ec;
        while (!rest.empty() && !parser.is_done()) {
            const std::size_t used = parser.put(boost::asio::buffer(rest.data(), rest.size()), ec);
            rest.remove_prefix(used);
            if (ec == bhttp::error::need_more) {
                ec = {};
                if (used == 0) break;
                continue;
            }
            if (ec) return 0;  // the server answers 400/413 and closes
        }
        if (!parser.is_done()) {
            parser.put_eof(ec);
            if (ec || !parser.is_done()) return 0;
        }
        Request req = parser.release();
        serve(req);
        if (!req.keep_alive()) break;
    }
    return 0;
}
