// rr-test-service: the four official Robot Raconteur test services (test_services.hpp) on the project's
// service API, for the official client suites and our own checks (docs/native-service.md).
//
//   rr-test-service [--port N] [--listen ADDR] [--nodename NAME] [--local] [--tls-cert PEM --tls-key PEM]
//                   [--robdef-dir DIR] [--official-values FILE] [--seed N] [--max-lifetime S]
//
//   --port N            TCP port (0, the default: any free one): rr+tcp, and rr+ws on the same port
//   --listen ADDR       address to listen on (default 127.0.0.1)
//   --nodename NAME     the NodeName (its NodeID from the rr+local NodeID cache), also served on rr+local
//   --local             serve rr+local without a NodeName (found by NodeID)
//   --tls-cert, --tls-key   PEM certificate chain and key: the port also takes TLS (rr+wss, rrs+tcp)
//   --robdef-dir DIR    the definitions com.robotraconteur.testing.TestService1…5.robdef
//                       (default: $RR_SHARED_DIR/robdef-testing, else the configured shared folder's)
//   --official-values FILE  the official test values (test_values.hpp); default: LFSR values only
//   --seed N            LFSR seed (default 55)
//   --max-lifetime S    exit after S seconds (a bound for test harnesses; default: none)
//
// When it accepts connections it prints one line, `ready ` and a JSON object: url (rr+tcp base URL,
// append `?service=NAME`), ws_url, wss_url (with TLS), local_url (with rr+local), port, nodeid,
// nodename, values ("lfsr" or "official"), services. It exits 0 on SIGTERM or SIGINT; 2 when it cannot
// start (the message says why).
#include <atomic>
#include <condition_variable>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "server/http/http_server.hpp"
#include "server/node/node.hpp"
#include "server/service/object_service.hpp"
#include "server/transport/local/local_listener.hpp"
#include "server/transport/tcp_listener.hpp"
#include "server/transport/tls/tls_context.hpp"
#include "server/transport/tls/tls_listener.hpp"
#include "test/testsvc/test_services.hpp"

#ifndef RR_TESTSVC_SHARED_DIR
#define RR_TESTSVC_SHARED_DIR "../shared"
#endif

using namespace rr;
using namespace rr::server;
using namespace rr::testsvc;

namespace {

volatile std::sig_atomic_t g_stop = 0;

[[noreturn]] void usage() {
    std::cerr << "usage: rr-test-service [--port N] [--listen ADDR] [--nodename NAME] [--local]\n"
                 "                       [--tls-cert PEM --tls-key PEM] [--robdef-dir DIR]\n"
                 "                       [--official-values FILE] [--seed N] [--max-lifetime S]\n";
    std::exit(2);
}

[[noreturn]] void cannot_start(const std::string& why) {
    std::cerr << "rr-test-service: " << why << std::endl;
    std::exit(2);
}

std::string default_robdef_dir() {
    if (const char* env = std::getenv("RR_SHARED_DIR"); env && *env) return std::string(env) + "/robdef-testing";
    return std::string(RR_TESTSVC_SHARED_DIR) + "/robdef-testing";
}

std::string read_text(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    if (!in) cannot_start("cannot read " + p.string());
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::shared_ptr<ObjectService> serve(const std::shared_ptr<Node>& node, const std::string& name,
                                     const std::shared_ptr<ServiceObject>& root) {
    auto svc = must(ObjectService::create(name, root), "service " + name);
    must(node->register_service(svc), "register " + name);
    return svc;
}

}  // namespace

int main(int argc, char** argv) {
    std::uint16_t port = 0;
    std::string listen_address = "127.0.0.1";
    std::optional<std::string> nodename, tls_cert, tls_key, official_values;
    bool local_by_id = false;
    std::string robdef_dir = default_robdef_dir();
    std::uint32_t seed = TestValues::kSeed;
    double max_lifetime = 0;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) usage();
            return argv[++i];
        };
        try {
            if (a == "--port") port = static_cast<std::uint16_t>(std::stoul(value()));
            else if (a == "--listen") listen_address = value();
            else if (a == "--nodename") nodename = value();
            else if (a == "--local") local_by_id = true;
            else if (a == "--tls-cert") tls_cert = value();
            else if (a == "--tls-key") tls_key = value();
            else if (a == "--robdef-dir") robdef_dir = value();
            else if (a == "--official-values") official_values = value();
            else if (a == "--seed") seed = static_cast<std::uint32_t>(std::stoul(value()));
            else if (a == "--max-lifetime") max_lifetime = std::stod(value());
            else usage();
        } catch (const std::exception&) {
            usage();
        }
    }
    if (tls_cert.has_value() != tls_key.has_value()) cannot_start("--tls-cert and --tls-key go together");

    struct sigaction sa {};
    sa.sa_handler = [](int) { g_stop = 1; };
    sigemptyset(&sa.sa_mask);
    sigaction(SIGTERM, &sa, nullptr);
    sigaction(SIGINT, &sa, nullptr);

    // The definitions (test data, read at run time: docs/native-service.md).
    std::vector<std::string> texts;
    for (int n : {1, 2, 3, 4, 5}) {
        const auto p = std::filesystem::path(robdef_dir) / ("com.robotraconteur.testing.TestService" + std::to_string(n) + ".robdef");
        if (!std::filesystem::exists(p)) cannot_start("no " + p.string() + " (give --robdef-dir or RR_SHARED_DIR)");
        texts.push_back(read_text(p));
    }
    auto types = must(ServiceTypes::create(std::move(texts)), "definitions in " + robdef_dir);
    std::shared_ptr<const TestValues> values =
        official_values ? std::make_shared<const TestValues>(must(TestValues::load_official(types, *official_values, seed), "--official-values"))
                        : std::make_shared<const TestValues>(types, seed);

    NodeOptions options;
    options.node_name = nodename.value_or("");
    std::optional<local::NodeNameReservation> reservation;
    if (nodename) {
        auto r = local::reserve_node_name(local::default_node_directories(), *nodename);
        if (!r) cannot_start("--nodename: " + r.error().message);
        options.node_id = r->node_id;
        reservation = std::move(*r);
    }
    auto node = Node::create(options);
    Context c{types, values, &node->io_context()};

    // The services, with the official names and settings.
    auto root1 = TestRoot::create(c);
    auto svc1 = serve(node, "RobotRaconteurTestService", root1->root());
    MapString attributes;
    attributes.entries.emplace_back("test", Value("This is a test attribute"));
    attributes.entries.emplace_back("test2", Value::scalar<std::int32_t>(42));
    must(svc1->set_attributes(std::move(attributes)), "attributes");
    root1->attach(svc1);

    auto root1_auth = TestRoot::create(c);
    auto svc1_auth = must(ObjectService::create("RobotRaconteurTestService_auth", root1_auth->root()), "auth service");
    PasswordTable users;  // the official test users (requirevaliduser; allowobjectlock)
    users.add_user("testuser1", "testpass1", {"objectlock"});
    users.add_user("testuser2", "testpass2", {"objectlock"});
    users.add_user("testsuperuser", "superpass1", {"objectlock", "objectlockoverride"});
    svc1_auth->set_users(std::move(users));
    must(node->register_service(svc1_auth), "register RobotRaconteurTestService_auth");
    root1_auth->attach(svc1_auth);

    auto root3 = TestRoot3::create(c);
    auto svc2 = serve(node, "RobotRaconteurTestService2", root3->root());
    root3->attach(svc2);

    auto svc3 = serve(node, "RobotRaconteurTestService3", make_async_test_root(c));

    // Transports: rr+tcp and rr+ws on one port, TLS (rr+wss, rrs+tcp) on it too with a certificate,
    // rr+local when named or asked for.
    auto http_server = std::make_shared<http::HttpServer>(node, http::HttpOptions{});
    TcpListenerOptions tcp;
    tcp.http = http::http_handler(http_server);
    if (tls_cert) {
        auto creds = TlsServerCredentials::load(TlsServerFiles{*tls_cert, *tls_key, "", "", ""});
        if (!creds) cannot_start("TLS: " + creds.error().message);
        auto tls = std::make_shared<TlsListenOptions>();
        tls->credentials = *creds;
        tls->node_id = node->node_id();
        tls->node_name = node->node_name();
        tls->timeout = node->options().first_bytes_timeout;
        tls->https = http::https_handler(http_server);
        tcp.tls = std::move(tls);
    }
    auto bound = listen_tcp(node, listen_address, port, std::move(tcp));
    if (!bound) cannot_start("listen on " + listen_address + ":" + std::to_string(port) + ": " + bound.error().message);
    std::shared_ptr<local::LocalListener> local_listener;
    if (nodename || local_by_id) {
        auto l = local::listen_local(node, {}, std::move(reservation));
        if (!l) cannot_start("rr+local: " + l.error().message);
        local_listener = *l;
    }

    // The broadcast pipe and wire of the TestService1 roots, every 25 ms (as the official service).
    std::mutex tick_mutex;
    std::condition_variable tick_cv;
    bool stopping = false;
    std::thread ticker([&] {
        std::unique_lock lock(tick_mutex);
        while (!tick_cv.wait_for(lock, std::chrono::milliseconds(25), [&] { return stopping; })) {
            lock.unlock();
            root1->tick();
            root1_auth->tick();
            lock.lock();
        }
    });

    const std::string host = listen_address == "0.0.0.0" || listen_address == "::" ? "127.0.0.1" : listen_address;
    const std::string authority = (host.find(':') != std::string::npos ? "[" + host + "]" : host) + ":" + std::to_string(*bound);
    nlohmann::json ready = {
        {"url", "rr+tcp://" + authority + "/"},
        {"ws_url", "rr+ws://" + authority + "/"},
        {"port", *bound},
        {"nodeid", node->node_id().to_braced_string()},
        {"nodename", node->node_name()},
        {"values", values->official() ? "official" : "lfsr"},
        {"services", {"RobotRaconteurTestService", "RobotRaconteurTestService_auth", "RobotRaconteurTestService2",
                      "RobotRaconteurTestService3"}},
    };
    if (tls_cert) ready["wss_url"] = "rr+wss://localhost:" + std::to_string(*bound) + "/";
    if (local_listener)
        ready["local_url"] = nodename ? "rr+local:///?nodename=" + *nodename : "rr+local:///?nodeid=" + node->node_id().to_string();
    std::cout << "ready " << ready.dump() << std::endl;

    const auto started = std::chrono::steady_clock::now();
    while (!g_stop) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        if (max_lifetime > 0 && std::chrono::steady_clock::now() - started > std::chrono::duration<double>(max_lifetime)) {
            std::cerr << "rr-test-service: --max-lifetime reached" << std::endl;
            break;
        }
    }

    {
        std::lock_guard lock(tick_mutex);
        stopping = true;
    }
    tick_cv.notify_all();
    ticker.join();
    if (local_listener) local_listener->close();
    node->shutdown();
    for (const auto& s : {svc1, svc1_auth, svc2, svc3}) s->shutdown();
    return 0;
}
