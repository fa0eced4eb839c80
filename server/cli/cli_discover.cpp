#include "server/cli/cli_discover.hpp"

#include <algorithm>
#include <thread>

#include "core/discovery/service_filter.hpp"
#include "server/cli/cli_target.hpp"
#include "server/cli/cli_usb.hpp"
#include "server/client/client.hpp"
#include "server/discovery/discovery_json.hpp"
#include "server/discovery/node_discovery.hpp"
#include "server/transport/local/local_discovery.hpp"

namespace rr::cli {

namespace {

using server::discovery::DiscoveryOptions;
using server::discovery::NodeDiscovery;
using server::discovery::NodeEntry;

bool wanted(const rr::discovery::ServiceInfo2& s, const std::vector<std::string>& types) {
    if (types.empty()) return true;
    rr::discovery::ServiceFilter f;
    f.service_types = types;
    return rr::discovery::match_service(f, s).has_value() ||
           std::find(types.begin(), types.end(), s.root_object_type) != types.end();
}

std::chrono::milliseconds seconds(double s) { return std::chrono::milliseconds(static_cast<long long>(s * 1000)); }

// This computer's rr+local nodes and the USB devices go into the same table as the network's
// (docs/discovery.md "Other sources"); their services are read over rr+local / rr+usb.
void add_local_and_usb_nodes(NodeDiscovery& d, double timeout_s, std::ostream& err) {
    for (const auto& n : server::local::find_local_nodes(server::local::default_node_directories()))
        d.add_node({n.node_id, n.node_name, n.urls, n.service_state_nonce, rr::discovery::NodeSource::local});
    auto usb = list_usb_devices(std::min(seconds(timeout_s), std::chrono::milliseconds(10000)));
    if (!usb) {
        if (usb.error().type != MessageErrorType::NotImplementedError)
            err << "rr: note: USB devices not listed: " << usb.error().message << std::endl;
        return;
    }
    for (const auto& u : *usb) {
        if (u.error) {
            err << "rr: " << u.description << ": " << u.error->message << std::endl;
            continue;
        }
        d.add_node({u.node_id, u.node_name, {u.url}, {}, rr::discovery::NodeSource::usb});
    }
}

}  // namespace

bool needs_discovery(const ConnectionUrl& url) {
    return url.host.empty() && (url.scheme == "rr+tcp" || url.scheme == "rrs+tcp") &&
           (!url.node_name.empty() || !url.node_id.is_any());
}

ExitCode run_discover(const CommandLine& cl, std::ostream& out, std::ostream& err) {
    auto io = command_io_threads(2);  // shared with rr+usb: service info is read from USB nodes too
    DiscoveryOptions o;
    o.listen = true;
    o.interfaces = cl.interfaces;
    auto d = NodeDiscovery::create(io->executor(), o);
    d->want_services(true);
    if (auto r = d->start(); !r) {
        err << "rr: " << error_name(r.error().type) << ": " << r.error().message << std::endl;
        return ExitCode::connect_failure;
    }
    add_local_and_usb_nodes(*d, cl.timeout_s, err);
    const auto deadline = std::chrono::steady_clock::now() + seconds(cl.timeout_s);
    // Wait the whole time (later nodes answer later), but stop early once every node found has answered
    // and at least half the time is gone.
    const auto half = std::chrono::steady_clock::now() + seconds(cl.timeout_s / 2);
    while (std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        if (std::chrono::steady_clock::now() < half) continue;
        auto nodes = d->nodes();
        bool all = !nodes.empty() && d->interrogations() == 0;
        for (const auto& n : nodes) all = all && (n.services.has_value() || !n.last_error.empty());
        if (all) break;
    }
    auto nodes = d->nodes();
    d->stop(std::chrono::milliseconds(6000));

    std::size_t shown = 0;
    for (const auto& n : nodes) {
        std::vector<const rr::discovery::ServiceInfo2*> services;
        if (n.services)
            for (const auto& s : *n.services)
                if (wanted(s, cl.types)) services.push_back(&s);
        if (!cl.types.empty() && services.empty()) continue;
        ++shown;
        if (cl.json) {
            auto j = server::discovery::node_json(n);
            if (n.services) {
                j["services"] = nlohmann::json::array();
                for (const auto* s : services) j["services"].push_back(server::discovery::service_json(*s));
            }
            out << json_line(j) << "\n";
            continue;
        }
        out << "node " << n.node_id.to_string() << "  " << (n.node_name.empty() ? "-" : n.node_name) << "  ("
            << rr::discovery::node_source_name(n.source) << ")\n";
        for (const auto& u : n.urls) out << "  url      " << u.url << "\n";
        if (!n.services) {
            out << "  services ? (" << (n.last_error.empty() ? "no answer in time" : n.last_error) << ")\n";
            continue;
        }
        for (const auto* s : services) {
            out << "  service  " << s->name << "  " << s->root_object_type;
            if (!s->connection_urls.empty()) out << "  " << s->connection_urls.front();
            out << "\n";
            for (const auto& [k, v] : s->attributes.entries) {
                auto j = server::discovery::service_json(*s)["attributes"][k];
                out << "           attribute " << k << " = " << json_line(j) << "\n";
            }
        }
    }
    out.flush();
    if (shown == 0) err << "rr: no nodes found" << (cl.types.empty() ? "" : " with services of that type") << std::endl;
    return ExitCode::ok;
}

Result<std::vector<std::string>> resolve_through_discovery(const ConnectionUrl& url, double timeout_s,
                                                           const std::vector<std::string>& interfaces) {
    auto io = command_io_threads(1);
    DiscoveryOptions o;
    o.listen = true;
    o.interfaces = interfaces;
    auto d = NodeDiscovery::create(io->executor(), o);
    if (auto r = d->start(); !r) return r.take_error();
    const auto deadline = std::chrono::steady_clock::now() + seconds(timeout_s);
    std::vector<NodeEntry> found;
    while (std::chrono::steady_clock::now() < deadline) {
        found.clear();
        for (auto& n : d->nodes()) {
            if (!url.node_id.is_any() && n.node_id != url.node_id) continue;
            if (!url.node_name.empty() && n.node_name != url.node_name) continue;
            found.push_back(std::move(n));
        }
        if (!found.empty()) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    std::vector<std::string> out;
    for (const auto& n : found)
        for (const auto& u : n.urls) {
            auto parsed = parse_connection_url(u.url);
            if (!parsed || parsed->scheme != url.scheme) continue;
            parsed->service = url.service.empty() ? std::string(rr::discovery::kServiceIndexName) : url.service;
            for (auto& c : d->connectable_urls(parsed->to_string())) out.push_back(std::move(c));
        }
    d->stop(std::chrono::milliseconds(6000));
    if (out.empty()) {
        std::string what = !url.node_name.empty() ? "NodeName \"" + url.node_name + "\"" : "NodeID " + url.node_id.to_string();
        return fail(MessageErrorType::NodeNotFound,
                    "no node with " + what + " found by discovery within " + std::to_string(timeout_s) + " s");
    }
    return out;
}

}  // namespace rr::cli
