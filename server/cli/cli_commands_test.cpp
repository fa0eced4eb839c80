// run_command in-process against a node whose service requires a login: credentials from the command
// line reach the service; wrong ones are a connect failure. (The end-to-end tests are test/cli/.)
#include <catch2/catch.hpp>

#include <sstream>

#include "server/cli/cli_commands.hpp"
#include "server/node/node.hpp"
#include "server/service/object_service.hpp"
#include "server/transport/tcp_listener.hpp"

using namespace rr;
using namespace rr::cli;
using namespace std::chrono_literals;

namespace {

struct LoginNode {
    std::shared_ptr<server::Node> node = server::Node::create(server::NodeOptions{NodeID(), "clitest.node", 2, {}, 0, 5000ms});
    std::shared_ptr<server::ObjectService> service;
    std::string url;

    LoginNode() {
        auto types = server::ServiceTypes::create(
            {"service example.clitest\n\nstdver 0.10\n\nobject Obj\n    property double value\nend\n"});
        REQUIRE(types);
        auto root = server::ServiceObject::create(*types, "example.clitest.Obj");
        REQUIRE(root);
        REQUIRE((*root)->set_property_value("value", Value::scalar(2.5)));
        auto s = server::ObjectService::create("clitest", *root);
        REQUIRE(s);
        service = *s;
        server::PasswordTable users;
        users.add_user("ada", "lovelace");
        service->set_users(std::move(users));
        REQUIRE(node->register_service(service));
        auto port = listen_tcp(node, "127.0.0.1", 0);
        REQUIRE(port);
        url = "rr+tcp://127.0.0.1:" + std::to_string(*port) + "/?service=clitest";
    }
    ~LoginNode() {
        service->shutdown();
        node->shutdown();
    }
};

struct Run {
    ExitCode code;
    std::string out, err;
};

Run run(std::vector<std::string> args) {
    auto cl = parse_command_line(args);
    REQUIRE(cl);
    std::ostringstream out, err;
    std::atomic<bool> stop{false};
    ExitCode code = run_command(*cl, out, err, stop);
    return {code, out.str(), err.str()};
}

}  // namespace

TEST_CASE("cli: --username and --password log in to a service that requires it") {
    LoginNode n;
    auto ok = run({"get", n.url, "value", "--username", "ada", "--password", "lovelace", "--timeout", "5"});
    CHECK(ok.code == ExitCode::ok);
    CHECK(ok.out == "2.5\n");
    CHECK(ok.err.empty());

    auto wrong = run({"get", n.url, "value", "--username", "ada", "--password", "babbage", "--timeout", "5"});
    CHECK(wrong.code == ExitCode::connect_failure);
    CHECK(wrong.out.empty());
    CHECK(wrong.err.rfind("rr: RobotRaconteur.AuthenticationError: ", 0) == 0);

    // Without credentials no session is made either.
    auto none = run({"get", n.url, "value", "--timeout", "5"});
    CHECK(none.code == ExitCode::connect_failure);
    CHECK(none.err.rfind("rr: RobotRaconteur.AuthenticationError: ", 0) == 0);
}

TEST_CASE("cli: set writes through the typed client and a bad URL is a usage error") {
    LoginNode n;
    auto set = run({"set", n.url, "value", "-1e300", "--username", "ada", "--password", "lovelace"});
    CHECK(set.code == ExitCode::ok);
    CHECK(set.out.empty());
    auto get = run({"get", n.url, "value", "--username", "ada", "--password", "lovelace"});
    CHECK(get.out == "-1e+300\n");
    auto bad = run({"get", "rr+tcp://127.0.0.1:notaport/?service=clitest", "value"});
    CHECK(bad.code == ExitCode::usage_error);
    CHECK(bad.err.find("InvalidArgument") != std::string::npos);
}
