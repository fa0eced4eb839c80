#include "server/gateway/auth/access_policy.hpp"

namespace rr::server::gateway::auth {

std::string_view operation_name(Operation op) noexcept {
    switch (op) {
        case Operation::read: return "read";
        case Operation::write: return "write";
        case Operation::call: return "call";
        case Operation::lock: return "lock";
        case Operation::record: return "record";
    }
    return "?";
}

bool AccessRule::allows(Operation op) const noexcept {
    switch (op) {
        case Operation::read: return read;
        case Operation::write: return write;
        case Operation::call: return call;
        case Operation::lock: return lock;
        case Operation::record: return record;
    }
    return false;
}

void AccessPolicy::add_role(std::string role, std::vector<AccessRule> rules) { roles_[std::move(role)] = std::move(rules); }

bool AccessPolicy::has_role(std::string_view role) const { return roles_.find(role) != roles_.end(); }

std::vector<std::string> AccessPolicy::role_names() const {
    std::vector<std::string> out;
    for (const auto& [name, rules] : roles_) out.push_back(name);
    return out;
}

bool AccessPolicy::glob_match(std::string_view p, std::string_view t) noexcept {
    // Iterative matching with one backtrack point (the last '*'): linear in practice, no recursion.
    std::size_t pi = 0, ti = 0, star = std::string_view::npos, mark = 0;
    while (ti < t.size()) {
        if (pi < p.size() && p[pi] == '*') {
            star = pi++;
            mark = ti;
        } else if (pi < p.size() && p[pi] == t[ti]) {
            ++pi;
            ++ti;
        } else if (star != std::string_view::npos) {
            pi = star + 1;
            ti = ++mark;
        } else {
            return false;
        }
    }
    while (pi < p.size() && p[pi] == '*') ++pi;
    return pi == p.size();
}

bool AccessPolicy::allows(const std::vector<std::string>& roles, std::string_view device, std::string_view member,
                          Operation op) const {
    for (const auto& role : roles) {
        auto it = roles_.find(role);
        if (it == roles_.end()) continue;
        for (const auto& rule : it->second) {
            if (!rule.allows(op)) continue;
            bool dev = false;
            for (const auto& d : rule.devices)
                if (glob_match(d, device)) {
                    dev = true;
                    break;
                }
            if (!dev) continue;
            for (const auto& m : rule.members)
                if (glob_match(m, member)) return true;
        }
    }
    return false;
}

std::string member_key(std::string_view object, std::string_view member) {
    if (object.empty()) return std::string(member);
    std::string out;
    out.reserve(object.size() + 1 + member.size());
    out.append(object).append(".").append(member);
    return out;
}

std::string refused_target(std::string_view key, Operation op) {
    if (op != Operation::lock) return std::string(key);
    return key.empty() ? std::string("the root object") : "object " + std::string(key);
}

}  // namespace rr::server::gateway::auth
