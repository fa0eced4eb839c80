// Failed-login rate limiting per client address (docs/security.md "Failed logins").
//
// Every failed login (RR AuthenticateUser / ConnectClientCombined, POST /api/login, a bad bearer token
// or JWT, a bad JSON WebSocket login) is recorded against the client's address. An address with
// `max_failures` failures within `window` is refused for `lockout`: every login attempt from it fails
// at once with "too many failed logins" without the password being looked at, whatever it is.
// A successful login clears the address's failures. At most `max_addresses` addresses are tracked
// (the stalest entry goes first), so a flood of addresses cannot grow memory without bound.
// Time is passed in (testable); thread-safe.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <string_view>

namespace rr::server::gateway::auth {

struct LoginLimits {
    unsigned max_failures = 5;
    std::chrono::seconds window{60};
    std::chrono::seconds lockout{300};
    std::size_t max_addresses = 10000;
};

class LoginLimiter {
public:
    using Clock = std::chrono::steady_clock;
    explicit LoginLimiter(LoginLimits limits = {}) : limits_(limits) {}

    /// Seconds the address must still wait (0 = may try now).
    std::int64_t blocked_for(std::string_view address, Clock::time_point now) const;
    /// A failed attempt; returns true when this failure locked the address out.
    bool failed(std::string_view address, Clock::time_point now);
    void succeeded(std::string_view address);
    const LoginLimits& limits() const noexcept { return limits_; }
    std::size_t tracked() const;

private:
    struct Entry {
        unsigned failures = 0;
        Clock::time_point first{}, locked_until{}, last{};
    };
    LoginLimits limits_;
    mutable std::mutex mutex_;
    std::map<std::string, Entry, std::less<>> entries_;
};

/// The address part of "ip:port", "[v6]:port", or an address alone (the limiter keys on addresses,
/// not ports).
std::string address_of(std::string_view peer);

}  // namespace rr::server::gateway::auth
