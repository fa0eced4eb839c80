#include "server/gateway/auth/gateway_auth.hpp"

#include <catch2/catch.hpp>

#include "base/message/error_entry.hpp"

using namespace rr::server::gateway::auth;
using namespace std::chrono_literals;

namespace {

rr::MessageElement password_credentials(const std::string& pw, bool with_password = true) {
    rr::MessageElement creds;
    creds.name = "credentials";
    creds.type = rr::DataTypes::dictionary_t;
    if (with_password) creds.elements.push_back(rr::make_string_element("password", pw));
    return creds;
}

struct Fixture {
    std::chrono::steady_clock::time_point now = std::chrono::steady_clock::time_point{} + 10000s;
    std::shared_ptr<GatewayAuth> auth;
    explicit Fixture(bool with_tokens = true) {
        GatewayAuthSettings s;
        s.users.add_user("alice", "alice-pw", {"operator", "objectlock"});
        s.users.add_user("bob", "bob-pw", {"viewer"});
        if (with_tokens) s.tokens = *BearerTokens::parse("wall-display-token-0123456789 wall viewer\n");
        auto p = std::make_shared<AccessPolicy>();
        p->add_role("viewer", {AccessRule{{"*"}, {"*"}, true, false, false}});
        p->add_role("operator", {AccessRule{{"*"}, {"*"}, true, true, true}});
        s.policy = p;
        s.limits = LoginLimits{3, 60s, 120s, 100};
        s.session_ttl = 3600s;
        s.steady_now = [this] { return now; };
        auth = std::make_shared<GatewayAuth>(std::move(s));
    }
};

}  // namespace

TEST_CASE("gateway auth: RR and HTTP password logins give the user's roles") {
    Fixture f;
    CHECK(f.auth->enabled());
    auto cred = password_credentials("alice-pw");
    auto a = f.auth->login_rr("alice", &cred, "10.0.0.1:4000");
    REQUIRE(a);
    CHECK((*a)->name == "alice");
    CHECK((*a)->allows("create", "Drive", Operation::call));
    auto bad = password_credentials("nope");
    auto r = f.auth->login_rr("alice", &bad, "10.0.0.1:4000");
    REQUIRE_FALSE(r);
    CHECK(r.error().message == "Invalid username or password");
    CHECK(f.auth->counters().failed_rr == 1);
    auto no_pw = password_credentials("", false);
    CHECK(f.auth->login_rr("alice", &no_pw, "x").error().message == "Password not supplied in credentials");

    auto b = f.auth->login_password("bob", "bob-pw", "10.0.0.2:1", LoginChannel::http);
    REQUIRE(b);
    CHECK((*b)->allows("create", "Bumpers", Operation::read));
    CHECK_FALSE((*b)->allows("create", "Drive", Operation::call));
    CHECK_FALSE(f.auth->login_password("bob", "alice-pw", "10.0.0.2:1", LoginChannel::http));
    CHECK_FALSE(f.auth->login_password("nobody", "x", "10.0.0.2:1", LoginChannel::http));
    CHECK(f.auth->counters().failed_http == 2);
    CHECK(f.auth->principal_for_user("bob") == *b);
    CHECK(f.auth->principal_for_user("eve") == nullptr);
}

TEST_CASE("gateway auth: brute force from one address is refused, others are not") {
    Fixture f;
    for (int i = 0; i < 3; ++i) CHECK_FALSE(f.auth->login_password("alice", "guess" + std::to_string(i), "198.51.100.7:1", LoginChannel::http));
    CHECK(f.auth->counters().lockouts == 1);
    // Now even the right password is refused from that address, over RR too.
    auto right = f.auth->login_password("alice", "alice-pw", "198.51.100.7:2", LoginChannel::http);
    REQUIRE_FALSE(right);
    CHECK(right.error().message.find("Too many failed logins") != std::string::npos);
    auto cred = password_credentials("alice-pw");
    CHECK_FALSE(f.auth->login_rr("alice", &cred, "198.51.100.7:3"));
    CHECK_FALSE(f.auth->login_token("wall-display-token-0123456789", "198.51.100.7:3", LoginChannel::token));
    CHECK(f.auth->counters().rate_limited == 3);
    CHECK(f.auth->login_password("alice", "alice-pw", "198.51.100.8:1", LoginChannel::http));
    f.now += 121s;
    CHECK(f.auth->login_password("alice", "alice-pw", "198.51.100.7:2", LoginChannel::http));
}

TEST_CASE("gateway auth: tokens and cookie sessions") {
    Fixture f;
    auto t = f.auth->login_token("wall-display-token-0123456789", "10.0.0.1:1", LoginChannel::token);
    REQUIRE(t);
    CHECK((*t)->name == "wall");
    CHECK((*t)->allows("create", "Bumpers", Operation::read));
    std::string why;
    CHECK_FALSE(f.auth->login_token("wall-display-token-012345678X", "10.0.0.1:1", LoginChannel::token, &why));
    CHECK(why == "unknown bearer token");
    CHECK(f.auth->counters().failed_token == 1);

    auto id = f.auth->open_session(*t);
    CHECK(id.size() == 64);
    CHECK(f.auth->session(id) == *t);
    CHECK(f.auth->session(id + "0") == nullptr);
    CHECK(f.auth->session("") == nullptr);
    auto id2 = f.auth->open_session(*t);
    CHECK(id2 != id);
    f.auth->close_session(id2);
    CHECK(f.auth->session(id2) == nullptr);
    f.now += 3601s;
    CHECK(f.auth->session(id) == nullptr);  // expired
}

TEST_CASE("gateway auth: nothing configured = off") {
    GatewayAuth a(GatewayAuthSettings{});
    CHECK_FALSE(a.enabled());
    CHECK_FALSE(a.has_users());
}

TEST_CASE("gateway auth: a web session's cookie names the RR user of an rr+ws session") {
    Fixture f;
    auto bob = f.auth->login_password("bob", "bob-pw", "10.0.0.1:1", LoginChannel::http);
    REQUIRE(bob);
    auto id = f.auth->open_session(*bob);
    auto name = f.auth->web_rr_user("theme=dark; rrgw_session=" + id + "; other=1");
    REQUIRE(name);
    CHECK(*name == "bob");
    CHECK(f.auth->principal_for_user("bob") == *bob);
    auto wall = f.auth->login_token("wall-display-token-0123456789", "10.0.0.1:1", LoginChannel::token);
    REQUIRE(wall);
    auto wid = f.auth->open_session(*wall);
    auto wname = f.auth->web_rr_user("rrgw_session=" + wid);
    REQUIRE(wname);
    CHECK(*wname == "wall@token");
    CHECK(f.auth->principal_for_user("wall@token") == *wall);
    CHECK(f.auth->principal_for_user("wall") == nullptr);
    CHECK_FALSE(f.auth->web_rr_user("rrgw_session=deadbeef"));
    CHECK_FALSE(f.auth->web_rr_user(""));
    CHECK_FALSE(f.auth->web_rr_user("other=" + id));
}

TEST_CASE("gateway auth: reload swaps users, tokens and roles, and sessions follow their user") {
    Fixture f;
    auto alice = f.auth->login_password("alice", "alice-pw", "10.0.0.1:1", LoginChannel::http);
    auto bob = f.auth->login_password("bob", "bob-pw", "10.0.0.1:1", LoginChannel::http);
    auto wall = f.auth->login_token("wall-display-token-0123456789", "10.0.0.3:1", LoginChannel::token);
    REQUIRE((alice && bob && wall));
    const auto alice_session = f.auth->open_session(*alice);
    const auto bob_session = f.auth->open_session(*bob);
    const auto wall_session = f.auth->open_session(*wall);
    auto wall_rr = f.auth->web_rr_user("rrgw_session=" + wall_session);
    REQUIRE(wall_rr);
    REQUIRE(f.auth->principal_for_user(*wall_rr));

    // The new files: alice gone, bob an operator now, carol new; another token; viewer may not read.
    GatewayAuthSettings fresh;
    fresh.users.add_user("bob", "bob-pw2", {"operator"});
    fresh.users.add_user("carol", "carol-pw", {"viewer"});
    fresh.tokens = *BearerTokens::parse("kiosk-token-abcdefghijklmnopqrstuvwxyz kiosk viewer\n");
    auto p = std::make_shared<AccessPolicy>();
    p->add_role("viewer", {AccessRule{{"*"}, {"Bumpers"}, true, false, false}});
    p->add_role("operator", {AccessRule{{"*"}, {"*"}, true, true, true}});
    fresh.policy = p;
    REQUIRE(f.auth->reload(std::move(fresh)));
    CHECK(f.auth->summary().users == 2);
    CHECK(f.auth->summary().tokens == 1);
    CHECK(describe(f.auth->summary()) == "2 user(s), 1 token(s), 2 role(s)");

    CHECK_FALSE(f.auth->login_password("alice", "alice-pw", "10.0.0.4:1", LoginChannel::http));
    CHECK_FALSE(f.auth->login_password("bob", "bob-pw", "10.0.0.4:1", LoginChannel::http));
    auto bob2 = f.auth->login_password("bob", "bob-pw2", "10.0.0.4:1", LoginChannel::http);
    REQUIRE(bob2);
    CHECK((*bob2)->allows("create", "Drive", Operation::call));
    auto carol_cred = password_credentials("carol-pw");
    auto carol = f.auth->login_rr("carol", &carol_cred, "10.0.0.4:1");
    REQUIRE(carol);
    CHECK((*carol)->allows("create", "Bumpers", Operation::read));
    CHECK_FALSE((*carol)->allows("create", "Drive", Operation::read));
    CHECK_FALSE(f.auth->login_token("wall-display-token-0123456789", "10.0.0.5:1", LoginChannel::token));
    CHECK(f.auth->login_token("kiosk-token-abcdefghijklmnopqrstuvwxyz", "10.0.0.5:1", LoginChannel::token));

    // Sessions: alice's ends, bob's carries his new roles, the token's ends (and its RR user's roles).
    CHECK_FALSE(f.auth->session(alice_session));
    auto bob_now = f.auth->session(bob_session);
    REQUIRE(bob_now);
    CHECK(bob_now->allows("create", "Drive", Operation::call));
    CHECK_FALSE(f.auth->session(wall_session));
    CHECK_FALSE(f.auth->principal_for_user(*wall_rr));
    // An RR session of a user still in the file is checked against the new roles.
    REQUIRE(f.auth->principal_for_user("bob"));
    CHECK(f.auth->principal_for_user("bob")->allows("create", "Drive", Operation::call));
    CHECK_FALSE(f.auth->principal_for_user("alice"));
}

TEST_CASE("gateway auth: a reload without users, tokens or key is refused and changes nothing") {
    Fixture f;
    GatewayAuthSettings empty;
    auto r = f.auth->reload(std::move(empty));
    REQUIRE_FALSE(r);
    CHECK(r.error().type == rr::MessageErrorType::InvalidConfiguration);
    CHECK(r.error().message.find("restart") != std::string::npos);
    CHECK(f.auth->enabled());
    CHECK(f.auth->login_password("alice", "alice-pw", "10.0.0.1:1", LoginChannel::http));
    CHECK(f.auth->summary().users == 2);
}

TEST_CASE("gateway auth: RR logins with a bearer token in the credentials") {
    Fixture f;
    auto token_credentials = [](const std::string& token) {
        rr::MessageElement creds;
        creds.name = "credentials";
        creds.type = rr::DataTypes::dictionary_t;
        creds.elements.push_back(rr::make_string_element("token", token));
        return creds;
    };
    auto good = token_credentials("wall-display-token-0123456789");
    auto who = f.auth->login_rr("wall@token", &good, "10.0.0.1:1");
    REQUIRE(who);
    CHECK((*who)->name == "wall");
    // The session's user name finds the token's principal (its roles), not a password user's.
    CHECK(f.auth->principal_for_user("wall@token") == *who);
    CHECK(f.auth->principal_for_user("wall") == nullptr);

    // The user name must be the one the token logs in as: a token cannot take alice's name and roles.
    auto as_alice = f.auth->login_rr("alice", &good, "10.0.0.1:1");
    REQUIRE_FALSE(as_alice);
    CHECK(as_alice.error().type == rr::MessageErrorType::AuthenticationError);
    CHECK(as_alice.error().message == "this token logs in as user \"wall@token\"; connect with that username");

    auto bad = token_credentials("wall-display-token-012345678X");
    auto refused = f.auth->login_rr("wall@token", &bad, "10.0.0.2:1");
    REQUIRE_FALSE(refused);
    CHECK(refused.error().message == "Invalid token");
    CHECK(f.auth->counters().failed_rr == 1);
    // Failed token logins count toward the address's lockout like failed passwords (limit 3 here).
    CHECK_FALSE(f.auth->login_rr("wall@token", &bad, "10.0.0.2:1"));
    CHECK_FALSE(f.auth->login_rr("wall@token", &bad, "10.0.0.2:1"));
    auto locked = f.auth->login_rr("wall@token", &good, "10.0.0.2:1");
    REQUIRE_FALSE(locked);
    CHECK(locked.error().message.find("Too many failed logins") != std::string::npos);
}
