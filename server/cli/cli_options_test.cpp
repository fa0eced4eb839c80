#include "server/cli/cli_options.hpp"

#include <catch2/catch.hpp>

using namespace rr;
using namespace rr::cli;

namespace {
rr::Result<rr::cli::CommandLine> parse(std::vector<std::string> a) { return parse_command_line(a); }
}  // namespace

// Member paths and --object are object paths (base/names/object_path.hpp): the CLI keeps the core's
// segments and messages, so these check the hand-over, not the parser again.
TEST_CASE("cli: member paths through objrefs go through core's object path parser") {
    auto q = parse({"get", "u", "child_by_name[with space.and dots].leaf.x"});
    REQUIRE(q);
    REQUIRE(q->objects.size() == 2);
    CHECK(q->objects[0].name == "child_by_name");
    CHECK(q->objects[0].has_index);
    CHECK(q->objects[0].index == "with space.and dots");  // a key holds any character but ']'
    CHECK(q->objects[1].name == "leaf");
    CHECK_FALSE(q->objects[1].has_index);
    CHECK(q->member == "x");

    auto minus = parse({"get", "u", "child_by_int[-1].value"});
    REQUIRE(minus);
    CHECK(minus->objects[0].index == "-1");
    auto encoded = parse({"get", "u", "child_by_int[%2d1].value"});  // service-path encoding, decoded
    REQUIRE(encoded);
    CHECK(encoded->objects[0].index == "-1");

    // --object comes first, then the member path's objrefs
    auto both = parse({"get", "u", "leaf.x", "--object", "child_by_name[a]"});
    REQUIRE(both);
    REQUIRE(both->objects.size() == 2);
    CHECK(both->objects[0].index == "a");
    CHECK(both->objects[1].name == "leaf");
    CHECK(both->member == "x");

    struct Bad {
        std::vector<std::string> args;
        std::string message;
    };
    const std::vector<Bad> bad = {
        {{"get", "u", ".x"}, "object path \".x\": expected a member name at offset 0"},
        {{"get", "u", "a..b"}, "object path \"a..b\": expected a member name at offset 2"},
        {{"get", "u", "a."}, "object path \"a.\" ends with '.'"},
        {{"get", "u", "a[1"}, "object path \"a[1\": '[' without ']'"},
        {{"get", "u", "a[].x"}, "object path \"a[].x\": empty index"},
        {{"get", "u", "a]"}, "object path \"a]\": unexpected ']' at offset 1"},
        {{"get", "u", "a[1]b"}, "object path \"a[1]b\": unexpected 'b' at offset 4"},
        {{"get", "u", "[1]"}, "object path \"[1]\": expected a member name at offset 0"},
        {{"get", "u", ""}, "object path \"\" is empty"},
        {{"info", "u", "--object", "child_by_name[with]dots]"}, "object path \"child_by_name[with]dots]\": unexpected 'd' at offset 19"},
        {{"get", "u", "child.value[3]"}, "the member itself takes no [key]: \"child.value[3]\""},
    };
    for (const auto& b : bad) {
        INFO(b.args.back());
        auto r = parse(b.args);
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::InvalidArgument);
        CHECK(r.error().message == b.message);
    }
}

TEST_CASE("cli: commands and their arguments") {
    auto c = parse({"call", "rr+tcp://h:1/?service=s", "child.leaf.scaled", "-2.5", "--timeout", "3"});
    REQUIRE(c);
    CHECK(c->kind == CommandKind::call);
    CHECK(c->url == "rr+tcp://h:1/?service=s");
    REQUIRE(c->objects.size() == 2);
    CHECK(c->objects[1].name == "leaf");
    CHECK(c->member == "scaled");
    CHECK(c->values == std::vector<std::string>{"-2.5"});  // a negative number is an argument
    CHECK(c->timeout_s == 3);

    auto o = parse({"get", "--object=child_by_int[7]", "u", "value"});
    REQUIRE(o);
    REQUIRE(o->objects.size() == 1);
    CHECK(o->objects[0].name == "child_by_int");
    CHECK(o->objects[0].index == "7");
    CHECK(o->member == "value");

    auto t = parse({"info", "rr+wss://h:443/?service=s", "--tls-ca", "ca.pem", "--http-login=alice:won:der"});
    REQUIRE(t);
    CHECK(t->tls_ca_file == "ca.pem");
    auto m = parse({"get", "rrs+tcp://h/?service=s", "x", "--tls-cert", "me.pem", "--tls-key=me.key"});
    REQUIRE(m);
    CHECK(m->tls_certificate_file == "me.pem");
    CHECK(m->tls_private_key_file == "me.key");
    CHECK(t->http_login == "alice:won:der");  // the password may hold colons

    auto w = parse({"watch", "u", "w_state", "--count", "3", "--seconds", "1.5"});
    REQUIRE(w);
    CHECK(w->count == 3u);
    CHECK(w->seconds == 1.5);

    auto i = parse({"info", "u", "--username", "a", "--password", "b"});
    REQUIRE(i);
    CHECK(i->kind == CommandKind::info);
    CHECK(i->username == "a");
    CHECK(i->password == "b");
    CHECK_FALSE(i->member);
    auto tk = parse({"get", "u", "p", "--username", "wall@token", "--token", "tok"});
    REQUIRE(tk);
    CHECK(tk->username == "wall@token");
    CHECK(tk->token == "tok");
    CHECK(tk->password.empty());

    auto h = parse({"get", "--help"});
    REQUIRE(h);
    CHECK(h->kind == CommandKind::help);
    CHECK(h->help_topic == "get");
    CHECK(help_text("get").find("usage: rr get") == 0);
    CHECK(help_text("nosuch").empty());
}

TEST_CASE("cli: usage errors") {
    const std::vector<std::vector<std::string>> bad = {
        {},
        {"frobnicate", "u"},
        {"get", "u"},
        {"set", "u", "m"},
        {"info", "u", "extra"},
        {"get", "u", "m", "--timeout", "0"},
        {"get", "u", "m", "--timeout"},
        {"get", "u", "m", "--count", "2"},
        {"watch", "u", "m", "--count", "x"},
        {"get", "u", "m", "--bogus", "1"},
        {"get", "u", "m[1]"},
        {"info", "u", "--http-login", "alice"},
    };
    for (const auto& a : bad) {
        std::string joined;
        for (const auto& s : a) joined += s + " ";
        INFO(joined);
        auto r = parse(a);
        REQUIRE_FALSE(r);
        CHECK(r.error().type == MessageErrorType::InvalidArgument);
        CHECK_FALSE(r.error().message.empty());
    }
}

TEST_CASE("cli: record and replay command lines") {
    auto r = parse({"record", "rr+tcp://h:1/?service=s", "--duration", "2.5", "--dir", "/tmp/x", "--members", "a,b",
                    "--encoding", "json", "--prefix", "p", "--name", "n"});
    REQUIRE(r);
    CHECK(r->kind == CommandKind::record);
    CHECK(r->url == "rr+tcp://h:1/?service=s");
    CHECK(r->duration == 2.5);
    CHECK(r->directory == "/tmp/x");
    CHECK(r->record_members == std::vector<std::string>{"a", "b"});
    CHECK(r->encoding == "json");
    CHECK(r->prefix == "p");
    CHECK(r->device_name == "n");
    auto both = parse({"record", "u", "--encoding", "both"});
    REQUIRE(both);
    CHECK(both->encoding.empty());
    CHECK_FALSE(both->duration);

    auto p = parse({"replay", "f.mcap", "--port", "8000", "--speed", "2", "--loop", "--address", "::1"});
    REQUIRE(p);
    CHECK(p->kind == CommandKind::replay);
    CHECK(p->file == "f.mcap");
    CHECK(p->port == 8000);
    CHECK(p->speed == 2.0);
    CHECK(p->loop);
    CHECK(p->address == "::1");

    for (auto bad : std::vector<std::vector<std::string>>{
             {"record"}, {"record", "u", "v"}, {"record", "u", "--members", "a,,b"}, {"record", "u", "--encoding", "xml"},
             {"record", "u", "--duration", "0"}, {"record", "u", "--port", "1"}, {"replay"}, {"replay", "f", "--dir", "d"},
             {"replay", "f", "--speed", "0"}, {"replay", "f", "--port", "70000"}, {"get", "u", "m", "--loop"}}) {
        INFO((bad.size() > 1 ? bad[1] : bad[0]));
        auto e = parse(bad);
        REQUIRE_FALSE(e);
        CHECK(e.error().type == MessageErrorType::InvalidArgument);
    }
    CHECK_FALSE(help_text("record").empty());
    CHECK_FALSE(help_text("replay").empty());
}
