#include "server/http/http_server.hpp"

#include "server/http/http_session.hpp"

namespace rr::server::http {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace bhttp = boost::beast::http;
namespace websocket = boost::beast::websocket;
using tcp = asio::ip::tcp;

using detail::HttpSession;
using detail::iequals;


bool same_origin(std::string_view origin, std::string_view host, std::string_view only_scheme) {
    if (host.empty()) return false;
    for (std::string_view scheme : {"http://", "https://"}) {
        if (!only_scheme.empty() && scheme.substr(0, scheme.size() - 3) != only_scheme) continue;
        if (origin.size() == scheme.size() + host.size() && iequals(origin.substr(0, scheme.size()), scheme) &&
            iequals(origin.substr(scheme.size()), host))
            return true;
    }
    return false;
}

bool websocket_deflate_allowed(const HttpOptions& options, std::string_view target) {
    if (options.websocket_deflate) return true;
    const std::string_view path = target.substr(0, target.find_first_of("?#"));
    for (const auto& p : options.websocket_deflate_paths) {
        const std::string_view base = p.size() > 1 && p.back() == '/' ? std::string_view(p).substr(0, p.size() - 1) : std::string_view(p);
        if (path == base || base == "/" || (path.size() > base.size() && path.substr(0, base.size()) == base && path[base.size()] == '/'))
            return true;
    }
    return false;
}

bool origin_allowed(const std::vector<std::string>& allowlist, std::string_view origin) {
    for (const auto& entry : allowlist) {
        std::string_view e(entry);
        if (e == "*" || iequals(e, origin)) return true;
        auto sep = e.find("://");
        if (sep == std::string_view::npos) continue;
        if (sep + 3 == e.size()) {  // "scheme://" matches any origin of that scheme
            if (origin.size() > e.size() && iequals(origin.substr(0, e.size()), e)) return true;
            continue;
        }
        auto osep = origin.find("://");
        if (osep == std::string_view::npos || !iequals(origin.substr(0, osep), e.substr(0, sep))) continue;
        auto ehost = e.substr(sep + 3);
        auto ohost = origin.substr(osep + 3);
        if (ehost.rfind("*.", 0) == 0) {  // "scheme://*.domain[:port]" matches subdomains
            auto suffix = ehost.substr(1);
            if (ohost.size() > suffix.size() && iequals(ohost.substr(ohost.size() - suffix.size()), suffix)) return true;
        }
    }
    return false;
}

Response make_response(const Request& request, bhttp::status status, std::string body, std::string_view content_type) {
    Response r{status, request.version()};
    r.set(bhttp::field::server, "rr-gateway");
    r.set(bhttp::field::content_type, content_type);
    r.keep_alive(request.keep_alive());
    r.body() = std::move(body);
    return r;
}

HttpServer::HttpServer(std::weak_ptr<Node> node, HttpOptions options)
    : node_(std::move(node)), options_(std::move(options)) {}

void HttpServer::handle(tcp::socket socket, std::vector<std::byte> initial, std::shared_ptr<const void> hold) {
    auto session = std::make_shared<HttpSession<beast::tcp_stream>>(shared_from_this(), beast::tcp_stream(std::move(socket)));
    session->start(std::move(initial), std::move(hold));
}

HttpHandler http_handler(std::weak_ptr<HttpServer> server) {
    return [server = std::move(server)](tcp::socket socket, std::vector<std::byte> initial, std::shared_ptr<const void> hold) {
        if (auto s = server.lock()) return s->handle(std::move(socket), std::move(initial), std::move(hold));
        boost::system::error_code ignored;
        socket.close(ignored);
    };
}

namespace {
WatchedRouteHandler unwatched(RouteHandler handler) {
    return [handler = std::move(handler)](const Request& req, Responder respond, const std::shared_ptr<RequestConnection>&) {
        handler(req, std::move(respond));
    };
}
}  // namespace

void HttpServer::add_route(bhttp::verb method, std::string path, RouteHandler handler, bool prefix) {
    routes_.push_back(Route{method, std::move(path), prefix, unwatched(std::move(handler))});
}

void HttpServer::add_route_any_method(std::string path, RouteHandler handler, bool prefix) {
    routes_.push_back(Route{std::nullopt, std::move(path), prefix, unwatched(std::move(handler))});
}

void HttpServer::add_watched_route(bhttp::verb method, std::string path, WatchedRouteHandler handler, bool prefix) {
    routes_.push_back(Route{method, std::move(path), prefix, std::move(handler)});
}

void HttpServer::track_socket(const std::shared_ptr<JsonSocket>& socket) {
    {
        std::lock_guard lock(sockets_mutex_);
        if (!going_away_) {
            if (sockets_.size() >= 64 && sockets_.size() == sockets_.capacity())
                std::erase_if(sockets_, [](const std::weak_ptr<JsonSocket>& w) { return w.expired(); });
            sockets_.push_back(socket);
            return;
        }
    }
    socket->close_going_away();
}

void HttpServer::go_away() {
    std::vector<std::weak_ptr<JsonSocket>> sockets;
    {
        std::lock_guard lock(sockets_mutex_);
        going_away_ = true;
        sockets.swap(sockets_);
    }
    for (auto& w : sockets)
        if (auto s = w.lock()) s->close_going_away();
}

std::string HttpServer::subprotocol_names() const {
    std::string out;
    for (const auto& [name, handler] : subprotocols_) out += (out.empty() ? "" : ", ") + name;
    return out;
}

void HttpServer::add_subprotocol(std::string name, JsonSocketHandler handler) {
    subprotocols_.emplace(std::move(name), std::move(handler));
}

const WatchedRouteHandler* HttpServer::find_route(bhttp::verb method, std::string_view path, bool any_method) const {
    auto matches = [&](const Route& r) { return r.prefix ? path.rfind(r.path, 0) == 0 : path == r.path; };
    for (const auto& r : routes_)
        if (r.method && *r.method == method && matches(r)) return &r.handler;
    if (any_method)
        for (const auto& r : routes_)
            if (!r.method && matches(r)) return &r.handler;
    return nullptr;
}

const JsonSocketHandler* HttpServer::find_subprotocol(std::string_view name) const {
    auto it = subprotocols_.find(name);
    return it == subprotocols_.end() ? nullptr : &it->second;
}

}  // namespace rr::server::http
