#include "server/transport/local/local_layout.hpp"

#include <algorithm>

namespace rr::server::local {

namespace {

bool is_alpha(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
bool is_key_char(char c) { return is_alpha(c) || is_digit(c) || c == '_' || c == '+' || c == '.' || c == '-'; }

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
    return s;
}

}  // namespace

bool is_valid_node_name(std::string_view name) noexcept {
    if (name.empty() || !is_alpha(name.front())) return false;
    return std::all_of(name.begin(), name.end(),
                       [](char c) { return is_alpha(c) || is_digit(c) || c == '_' || c == '.' || c == '-'; });
}

bool is_valid_local_username(std::string_view name) noexcept {
    if (name.empty() || !is_alpha(name.front())) return false;
    return std::all_of(name.begin(), name.end(), [](char c) { return is_alpha(c) || is_digit(c) || c == '_' || c == '-'; });
}

InfoMap parse_info(std::string_view text) {
    InfoMap out;
    while (!text.empty()) {
        auto nl = text.find('\n');
        std::string_view line = text.substr(0, nl);
        text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
        line = trim(line);
        std::size_t k = 0;
        while (k < line.size() && is_key_char(line[k])) ++k;
        if (k == 0) continue;
        std::string_view key = line.substr(0, k);
        std::string_view rest = trim(line.substr(k));
        if (rest.empty() || rest.front() != ':') continue;
        out.insert_or_assign(std::string(key), std::string(trim(rest.substr(1))));
    }
    return out;
}

std::string format_info(const InfoMap& info) {
    std::string out;
    for (const auto& [k, v] : info) {
        out += k;
        out += ": ";
        out += v;
        out += '\n';
    }
    return out;
}

std::string local_listen_url(const NodeID& id) { return std::string(kLocalBaseUrl) + "?nodeid=" + id.to_string(); }

std::string private_entry_dir(const NodeDirectories& d) { return path_join(path_join(d.user_run_dir, "transport"), "local"); }
std::string private_socket_dir(const NodeDirectories& d) { return path_join(d.user_run_dir, "socket"); }
std::string public_search_dir(const NodeDirectories& d) { return path_join(d.system_run_dir, "transport/local"); }
std::string public_user_dir(const NodeDirectories& d, std::string_view user) { return path_join(public_search_dir(d), user); }

std::string by_nodeid_file(std::string_view entry_dir, const NodeID& id, std::string_view ext) {
    return path_join(path_join(entry_dir, "by-nodeid"), id.to_string() + "." + std::string(ext));
}

std::string by_nodename_file(std::string_view entry_dir, std::string_view name, std::string_view ext) {
    return path_join(path_join(entry_dir, "by-nodename"), std::string(name) + "." + std::string(ext));
}

std::string nodename_lock_file(const NodeDirectories& d, std::string_view name) {
    return path_join(path_join(d.user_run_dir, "nodeids"), std::string(name) + ".pid");
}

std::string nodeid_cache_file(const NodeDirectories& d, std::string_view name) {
    return path_join(path_join(d.user_config_dir, "nodeids"), name);
}

std::string nodeid_state_file(const NodeDirectories& d, std::string_view name) {
    return path_join(path_join(d.user_state_dir, "nodeids"), name);
}

std::string LocalTarget::describe() const {
    std::string s;
    if (!node_name.empty()) s = "named \"" + node_name + "\"";
    if (!node_id.is_any()) s += (s.empty() ? "with NodeID " : " with NodeID ") + node_id.to_string();
    if (!user.empty()) s += " of user \"" + user + "\"";
    return s;
}

Result<LocalTarget> local_target(const ConnectionUrl& url) {
    auto bad = [&](const std::string& why) {
        return fail(MessageErrorType::InvalidArgument, "invalid rr+local URL \"" + url.to_string() + "\": " + why);
    };
    if (url.scheme != "rr+local") return bad("scheme is not rr+local");
    if (url.port != 0) return bad("rr+local takes no port");
    if (!url.host.empty() && url.host != "localhost")
        return bad("host must be empty or \"localhost\", not \"" + url.host + "\"");
    if (!url.user.empty() && url.host != "localhost") return bad("a user needs the form user@localhost");
    if (!url.path.empty() && url.path != "/") return bad("path must be \"/\", not \"" + url.path + "\"");
    LocalTarget t;
    if (!url.user.empty()) {
        if (!is_valid_local_username(url.user)) return bad("\"" + url.user + "\" is an invalid user name");
        t.user = url.user;
    }
    if (url.node_id.is_any() && url.node_name.empty()) return bad("a NodeID and/or a NodeName must be given (nodeid=… or nodename=…)");
    if (!url.node_name.empty() && !is_valid_node_name(url.node_name))
        return bad("\"" + url.node_name + "\" is an invalid NodeName");
    t.node_id = url.node_id;
    t.node_name = url.node_name;
    return t;
}

std::vector<SearchDir> search_dirs(const NodeDirectories& d, std::string_view my_user, const LocalTarget& target) {
    std::vector<SearchDir> out;
    auto add = [&](std::string path, bool is_public) {
        for (const auto& s : out)
            if (s.path == path) return;
        out.push_back({std::move(path), is_public});
    };
    if (target.user.empty() || target.user == my_user) {
        add(private_entry_dir(d), false);
        add(public_user_dir(d, my_user), true);
        if (target.user.empty()) add(public_user_dir(d, "root"), true);
    } else {
        add(public_user_dir(d, target.user), true);
    }
    return out;
}

}  // namespace rr::server::local
