#include "server/app/gateway_config.hpp"

#include <cctype>
#include <charconv>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "base/names/connection_url.hpp"
#include "base/names/node_id.hpp"
#include "server/http/forwarded.hpp"
#include "server/record/recording_spec.hpp"

namespace rr::server::app {
namespace {

struct ConfigError {
    std::string text;
};

class Reader {
public:
    explicit Reader(std::string_view source) : source_(source) {}

    [[noreturn]] void error(const YAML::Node& at, const std::string& key, const std::string& problem) const {
        std::string where = std::string(source_);
        if (at.IsDefined() && at.Mark().line >= 0) where += ":" + std::to_string(at.Mark().line + 1);
        throw ConfigError{where + ": " + key + ": " + problem};
    }

    void check_keys(const YAML::Node& map, const std::string& path, const std::set<std::string>& allowed) const {
        if (!map.IsMap()) error(map, path, "expected a mapping");
        for (const auto& kv : map) {
            auto key = kv.first.as<std::string>();
            if (!allowed.count(key)) {
                std::string list;
                for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
                error(kv.first, path.empty() ? key : path + "." + key, "unknown key (expected one of: " + list + ")");
            }
        }
    }

    std::string string(const YAML::Node& n, const std::string& key) const {
        if (!n.IsScalar()) error(n, key, "expected a string");
        return n.as<std::string>();
    }

    bool boolean(const YAML::Node& n, const std::string& key) const {
        bool v = false;
        if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) error(n, key, "expected true or false");
        return v;
    }

    std::uint64_t unsigned_int(const YAML::Node& n, const std::string& key, std::uint64_t max) const {
        if (!n.IsScalar()) error(n, key, "expected a number");
        const auto& s = n.Scalar();
        std::uint64_t v = 0;
        auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
        if (s.empty() || ec != std::errc() || p != s.data() + s.size())
            error(n, key, "expected a non-negative integer, got \"" + s + "\"");
        if (v > max) error(n, key, "must be at most " + std::to_string(max));
        return v;
    }

    std::vector<std::string> string_list(const YAML::Node& n, const std::string& key) const {
        if (!n.IsSequence()) error(n, key, "expected a list of strings");
        std::vector<std::string> out;
        for (const auto& item : n) out.push_back(string(item, key));
        return out;
    }

private:
    std::string_view source_;
};

const std::set<std::string> kLogLevels{"trace", "debug", "info", "warning", "error", "fatal", "disable"};
const std::set<std::string> kLogFormats{"text", "json"};

// NodeName syntax of the official library's NodeID cache (wire.md §13): also what rr+local accepts.
bool valid_node_name(const std::string& name) {
    if (name.empty()) return true;
    if (!std::isalpha(static_cast<unsigned char>(name[0]))) return false;
    for (char ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '_' && ch != '.' && ch != '-') return false;
    return true;
}

bool names_usb(const GatewayConfig& c, std::string* key) {
    for (const auto& d : c.devices)
        if (d.url.rfind("rr+usb:", 0) == 0) {
            if (key) *key = "devices." + d.name + ".url";
            return true;
        }
    for (std::size_t i = 0; i < c.discover.size(); ++i)
        for (const auto& t : c.discover[i].filter.transport_schemes)
            if (t == "rr+usb") {
                if (key) *key = "discover[" + std::to_string(i) + "].transports";
                return true;
            }
    return false;
}

void validate(const GatewayConfig& c, const std::function<void(const std::string&, const std::string&)>& error) {
    if (std::string key; c.usb.enabled == UsbSettings::Mode::off && names_usb(c, &key))
        error(key, "rr+usb is turned off by usb.enabled: false (remove it, or enable USB)");
    if (!c.discover.empty() && !c.discovery.enabled)
        error("discover", "needs discovery, which --no-discovery turns off (remove one of them)");
    if (!valid_node_name(c.node_name))
        error("gateway.node_name", "not a NodeName (letters, digits, _ . -, starting with a letter): \"" + c.node_name + "\"");
    if (!c.node_id.empty() && !NodeID::parse(c.node_id)) error("gateway.node_id", "not a NodeID (UUID)");
    if (!kLogLevels.count(c.log_level)) error("gateway.log_level", "unknown level \"" + c.log_level + "\"");
    if (!kLogFormats.count(c.log_format)) error("gateway.log_format", "unknown format \"" + c.log_format + "\" (text or json)");
    if (c.max_message_size < 16 * 1024 || c.max_message_size > 100u * 1024u * 1024u)
        error("gateway.max_message_size", "must be between 16 KiB and 100 MiB");
    std::set<std::string> names;
    for (const auto& d : c.devices) {
        if (!names.insert(d.name).second) error("devices." + d.name, "duplicate device name");
    }
    for (std::size_t i = 0; i < c.record.size(); ++i)
        if (auto r = record::check_spec_bounds(c.record[i], c.recordings); !r)
            error("record[" + std::to_string(i) + "]", r.error().message);
    const auto& t = c.tls;
    if (!t.certificate.empty() && t.private_key.empty()) error("gateway.tls.private_key", "missing (the certificate's key)");
    if (t.certificate.empty() && (!t.private_key.empty() || !t.client_ca.empty() || !t.node_certificate.empty() || t.required))
        error("gateway.tls.certificate", "missing (TLS needs a certificate and its private key)");
    if (t.node_certificate.empty() != t.node_private_key.empty())
        error(t.node_certificate.empty() ? "gateway.tls.node_certificate" : "gateway.tls.node_private_key",
              "node_certificate and node_private_key go together");
}

// An attribute filter: "value", [values] (any of), or {any: [..], all: [..], none: [..], regex: ".." | [..]}.
rr::discovery::FilterAttributeGroup attribute_group(const YAML::Node& n, const Reader& r, const std::string& key) {
    using rr::discovery::FilterAttribute;
    using rr::discovery::FilterAttributeGroup;
    using rr::discovery::FilterOperation;
    auto exact = [](std::string v) { return FilterAttribute{"", std::move(v), {}, ""}; };
    FilterAttributeGroup g;
    g.operation = FilterOperation::op_or;
    if (n.IsScalar()) {
        g.attributes.push_back(exact(r.string(n, key)));
        return g;
    }
    if (n.IsSequence()) {
        for (auto& v : r.string_list(n, key)) g.attributes.push_back(exact(std::move(v)));
        return g;
    }
    r.check_keys(n, key, {"any", "all", "none", "regex"});
    g.operation = FilterOperation::op_and;
    auto sub = [&](const char* k, FilterOperation op) {
        if (auto l = n[k]) {
            FilterAttributeGroup s;
            s.operation = op;
            for (auto& v : r.string_list(l, key + "." + k)) s.attributes.push_back(exact(std::move(v)));
            g.groups.push_back(std::move(s));
        }
    };
    sub("any", FilterOperation::op_or);
    sub("all", FilterOperation::op_and);
    sub("none", FilterOperation::op_nor);
    if (auto re = n["regex"]) {
        FilterAttributeGroup s;
        s.operation = FilterOperation::op_or;
        std::vector<std::string> patterns = re.IsSequence() ? r.string_list(re, key + ".regex")
                                                            : std::vector<std::string>{r.string(re, key + ".regex")};
        for (auto& p : patterns) {
            std::shared_ptr<std::regex> compiled;
            try {
                compiled = std::make_shared<std::regex>(p, std::regex::ECMAScript);
            } catch (const std::regex_error& e) {
                r.error(re, key + ".regex", "bad regular expression \"" + p + "\": " + e.what());
            }
            s.attributes.push_back(FilterAttribute{
                "", "", [compiled](std::string_view v) { return std::regex_match(v.begin(), v.end(), *compiled); }, p});
        }
        g.groups.push_back(std::move(s));
    }
    return g;
}

void parse_discovery(const YAML::Node& root, const Reader& r, GatewayConfig& c) {
    if (auto d = root["discovery"]) {
        r.check_keys(d, "discovery", {"enabled", "announce", "ipv4_broadcast", "interfaces", "max_nodes", "node_expiry_ms", "local"});
        if (auto n = d["local"]) c.discovery.local = r.boolean(n, "discovery.local");
        if (auto n = d["node_expiry_ms"]) {
            c.discovery.node_expiry = std::chrono::milliseconds(r.unsigned_int(n, "discovery.node_expiry_ms", 3600000));
            if (c.discovery.node_expiry.count() < 1000) r.error(n, "discovery.node_expiry_ms", "must be at least 1000");
        }
        if (auto n = d["enabled"]) c.discovery.enabled = r.boolean(n, "discovery.enabled");
        if (auto n = d["announce"]) c.discovery.announce = r.boolean(n, "discovery.announce");
        if (auto n = d["ipv4_broadcast"]) c.discovery.ipv4_broadcast = r.boolean(n, "discovery.ipv4_broadcast");
        if (auto n = d["interfaces"]) c.discovery.interfaces = r.string_list(n, "discovery.interfaces");
        if (auto n = d["max_nodes"]) {
            c.discovery.max_nodes = r.unsigned_int(n, "discovery.max_nodes", 65536);
            if (c.discovery.max_nodes == 0) r.error(n, "discovery.max_nodes", "must be at least 1");
        }
    }
    auto list = root["discover"];
    if (!list) return;
    if (!list.IsSequence()) r.error(list, "discover", "expected a list of filters");
    std::size_t i = 0;
    for (const auto& d : list) {
        const std::string key = "discover[" + std::to_string(i++) + "]";
        r.check_keys(d, key,
                     {"type", "types", "name", "nodename", "nodeid", "nodes", "service", "services", "transports",
                      "attributes", "attributes_operation", "max", "username", "password", "backoff_max_ms"});
        DiscoverRule rule;
        auto& f = rule.filter;
        if (auto n = d["type"]) f.service_types.push_back(r.string(n, key + ".type"));
        if (auto n = d["types"])
            for (auto& t : r.string_list(n, key + ".types")) f.service_types.push_back(std::move(t));
        if (auto n = d["name"]) {
            rule.name_template = r.string(n, key + ".name");
            if (rule.name_template.empty()) r.error(n, key + ".name", "must not be empty");
        }
        rr::discovery::FilterNode node;
        if (auto n = d["nodename"]) node.node_name = r.string(n, key + ".nodename");
        if (auto n = d["nodeid"]) {
            auto id = NodeID::parse(r.string(n, key + ".nodeid"));
            if (!id) r.error(n, key + ".nodeid", "not a NodeID (UUID)");
            node.node_id = *id;
        }
        if (!node.node_name.empty() || !node.node_id.is_any()) f.nodes.push_back(node);
        if (auto n = d["nodes"]) {
            if (!n.IsSequence()) r.error(n, key + ".nodes", "expected a list of {nodename, nodeid}");
            for (const auto& e : n) {
                r.check_keys(e, key + ".nodes[]", {"nodename", "nodeid"});
                rr::discovery::FilterNode fn;
                if (auto x = e["nodename"]) fn.node_name = r.string(x, key + ".nodes[].nodename");
                if (auto x = e["nodeid"]) {
                    auto id = NodeID::parse(r.string(x, key + ".nodes[].nodeid"));
                    if (!id) r.error(x, key + ".nodes[].nodeid", "not a NodeID (UUID)");
                    fn.node_id = *id;
                }
                f.nodes.push_back(fn);
            }
        }
        if (auto n = d["service"]) f.service_names.push_back(r.string(n, key + ".service"));
        if (auto n = d["services"])
            for (auto& s : r.string_list(n, key + ".services")) f.service_names.push_back(std::move(s));
        if (auto n = d["transports"]) {
            f.transport_schemes = r.string_list(n, key + ".transports");
            for (const auto& t : f.transport_schemes)
                if (t != "rr+tcp" && t != "rr+local" && t != "rr+ws" && t != "rr+wss" && t != "rrs+tcp" && t != "rr+usb")
                    r.error(n, key + ".transports", "unknown transport scheme \"" + t + "\"");
        }
        if (auto n = d["attributes"]) {
            if (!n.IsMap()) r.error(n, key + ".attributes", "expected a mapping of attribute name to filter");
            for (const auto& kv : n) {
                auto name = kv.first.as<std::string>();
                f.attributes[name] = attribute_group(kv.second, r, key + ".attributes." + name);
            }
        }
        if (auto n = d["attributes_operation"]) {
            auto op = rr::discovery::parse_filter_operation(r.string(n, key + ".attributes_operation"));
            if (!op) r.error(n, key + ".attributes_operation", "expected and, or, nor or nand");
            f.attributes_operation = *op;
        }
        if (auto n = d["max"]) f.max_count = static_cast<std::uint32_t>(r.unsigned_int(n, key + ".max", 100000));
        if (auto n = d["username"]) rule.username = r.string(n, key + ".username");
        if (auto n = d["password"]) rule.password = r.string(n, key + ".password");
        if (auto n = d["backoff_max_ms"])
            rule.backoff_max = std::chrono::milliseconds(r.unsigned_int(n, key + ".backoff_max_ms", 3600000));
        c.discover.push_back(std::move(rule));
    }
    if (!c.discover.empty() && !c.discovery.enabled)
        r.error(root["discovery"]["enabled"], "discover",
                "needs discovery, which discovery.enabled: false turns off (remove one of them)");
}

// A USB id: an integer, hexadecimal with 0x (0x1209, as lsusb shows 1209) or decimal.
std::uint64_t usb_id(const YAML::Node& n, const Reader& r, const std::string& key, std::uint64_t max) {
    if (!n.IsScalar()) r.error(n, key, "expected a number (hexadecimal with 0x, e.g. 0x1209)");
    const auto& s = n.Scalar();
    std::uint64_t v = 0;
    const bool hex = s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
    const char* first = s.data() + (hex ? 2 : 0);
    auto [p, ec] = std::from_chars(first, s.data() + s.size(), v, hex ? 16 : 10);
    if (s.empty() || ec != std::errc() || p != s.data() + s.size())
        r.error(n, key, "expected a number (hexadecimal with 0x, e.g. 0x1209), got \"" + s + "\"");
    if (v > max) r.error(n, key, "must be at most " + std::to_string(max));
    return v;
}

void parse_usb(const YAML::Node& root, const Reader& r, GatewayConfig& c) {
    auto u = root["usb"];
    if (!u) return;
    r.check_keys(u, "usb", {"enabled", "allow", "hotplug", "poll_interval_ms"});
    if (auto n = u["enabled"]) {
        if (n.IsScalar() && n.Scalar() == "auto") {
            c.usb.enabled = UsbSettings::Mode::automatic;
        } else {
            bool on = false;
            if (!n.IsScalar() || !YAML::convert<bool>::decode(n, on)) r.error(n, "usb.enabled", "expected true, false or auto");
            c.usb.enabled = on ? UsbSettings::Mode::on : UsbSettings::Mode::off;
        }
    }
    if (auto n = u["hotplug"]) c.usb.hotplug = r.boolean(n, "usb.hotplug");
    if (auto n = u["poll_interval_ms"]) {
        c.usb.poll_interval = std::chrono::milliseconds(r.unsigned_int(n, "usb.poll_interval_ms", 3600000));
        if (c.usb.poll_interval.count() < 100) r.error(n, "usb.poll_interval_ms", "must be at least 100");
    }
    if (auto list = u["allow"]) {
        if (!list.IsSequence()) r.error(list, "usb.allow", "expected a list of {vid, pid, interface}");
        std::size_t i = 0;
        for (const auto& e : list) {
            const std::string key = "usb.allow[" + std::to_string(i++) + "]";
            r.check_keys(e, key, {"vid", "pid", "interface"});
            if (!e["vid"]) r.error(e, key + ".vid", "missing");
            if (!e["pid"]) r.error(e, key + ".pid", "missing");
            UsbAllowEntry a;
            a.vendor_id = static_cast<std::uint16_t>(usb_id(e["vid"], r, key + ".vid", 0xFFFF));
            a.product_id = static_cast<std::uint16_t>(usb_id(e["pid"], r, key + ".pid", 0xFFFF));
            if (auto n = e["interface"]) a.interface_number = static_cast<std::uint8_t>(usb_id(n, r, key + ".interface", 255));
            c.usb.allow.push_back(a);
        }
    }
    if (c.usb.enabled == UsbSettings::Mode::off) {
        std::string key;
        if (names_usb(c, &key)) r.error(u["enabled"], key, "rr+usb is turned off by usb.enabled: false (remove it, or enable USB)");
    }
}

// A duration in seconds between 0.05 and 10 (safety.hold_to_run_max_s).
std::chrono::milliseconds bound_seconds(const YAML::Node& n, const Reader& r, const std::string& key) {
    double v = 0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !(v >= 0.05 && v <= 10))
        r.error(n, key, "expected seconds between 0.05 and 10");
    return std::chrono::milliseconds(static_cast<std::int64_t>(v * 1000 + 0.5));
}

// `safety:` (docs/gateway-config.md "Motion safety").
void parse_safety(const YAML::Node& root, const Reader& r, GatewayConfig& c) {
    auto sn = root["safety"];
    if (!sn) return;
    r.check_keys(sn, "safety", {"hold_to_run_max_s", "standard_robot", "hold_to_run", "motions", "streams", "stops"});
    auto& s = c.safety;
    if (auto n = sn["hold_to_run_max_s"]) s.hold_to_run_max = bound_seconds(n, r, "safety.hold_to_run_max_s");
    if (auto n = sn["standard_robot"]) s.standard_robot = r.boolean(n, "safety.standard_robot");
    // Each list: entries naming a device and a member of its root object, plus their own keys.
    auto each = [&](const char* list, const std::set<std::string>& keys, auto&& add) {
        auto l = sn[list];
        if (!l) return;
        const std::string lk = std::string("safety.") + list;
        if (!l.IsSequence()) r.error(l, lk, "expected a list of {device, member, …}");
        std::size_t i = 0;
        for (const auto& e : l) {
            const std::string key = lk + "[" + std::to_string(i++) + "]";
            std::set<std::string> allowed = keys;
            allowed.insert({"device", "member"});
            r.check_keys(e, key, allowed);
            if (!e["device"]) r.error(e, key + ".device", "missing");
            if (!e["member"]) r.error(e, key + ".member", "missing");
            const std::string device = r.string(e["device"], key + ".device");
            const std::string member = r.string(e["member"], key + ".member");
            if (device.empty()) r.error(e["device"], key + ".device", "must not be empty");
            if (member.empty()) r.error(e["member"], key + ".member", "must not be empty");
            add(e, key, device, member);
        }
    };
    each("hold_to_run", {"timeout_arg", "timeout_unit"}, [&](const YAML::Node& e, const std::string& key, const std::string& device,
                                                             const std::string& member) {
        if (!e["timeout_arg"]) r.error(e, key + ".timeout_arg", "missing (the argument that is the call's timeout)");
        gateway::HoldToRunMember h{member, r.string(e["timeout_arg"], key + ".timeout_arg"), 1.0};
        if (auto n = e["timeout_unit"]) {
            const auto unit = r.string(n, key + ".timeout_unit");
            if (unit == "ms")
                h.unit_s = 0.001;
            else if (unit != "s")
                r.error(n, key + ".timeout_unit", "expected s or ms");
        }
        s.hold_to_run.push_back({device, std::move(h)});
    });
    each("motions", {"wait_arg"}, [&](const YAML::Node& e, const std::string& key, const std::string& device, const std::string& member) {
        gateway::UntimedMotionMember m{member, {}};
        if (auto n = e["wait_arg"]) m.wait_arg = r.string(n, key + ".wait_arg");
        s.motions.push_back({device, std::move(m)});
    });
    each("streams", {}, [&](const YAML::Node&, const std::string&, const std::string& device, const std::string& member) {
        s.streams.push_back({device, member});
    });
    each("stops", {"value"}, [&](const YAML::Node& e, const std::string& key, const std::string& device, const std::string& member) {
        gateway::StopMember stop{member, std::nullopt};
        if (auto n = e["value"]) {
            double v = 0;
            bool b = false;
            if (n.IsScalar() && YAML::convert<double>::decode(n, v))
                stop.value = v;
            else if (n.IsScalar() && YAML::convert<bool>::decode(n, b))
                stop.value = b ? 1 : 0;
            else
                r.error(n, key + ".value", "expected a number (an enum's value as its number) or true/false");
        }
        s.stops.push_back({device, std::move(stop)});
    });
}

// devices[].safety: the device's own bound and standard-robot switch.
void parse_device_safety(const YAML::Node& n, const Reader& r, const std::string& key, GatewayConfig& c, const std::string& device) {
    r.check_keys(n, key, {"hold_to_run_max_s", "standard_robot"});
    SafetyConfig::Override o;
    if (auto x = n["hold_to_run_max_s"]) o.hold_to_run_max = bound_seconds(x, r, key + ".hold_to_run_max_s");
    if (auto x = n["standard_robot"]) o.standard_robot = r.boolean(x, key + ".standard_robot");
    c.safety.overrides[device] = o;
}

std::vector<std::string> patterns(const YAML::Node& n, const Reader& r, const std::string& key) {
    std::vector<std::string> out = n.IsSequence() ? r.string_list(n, key) : std::vector<std::string>{r.string(n, key)};
    if (out.empty()) r.error(n, key, "empty list (use \"*\" for all)");
    for (const auto& p : out)
        if (p.empty()) r.error(n, key, "empty pattern");
    return out;
}

void parse_auth(const YAML::Node& a, const Reader& r, GatewayAuthConfig& c) {
    r.check_keys(a, "gateway.auth", {"users", "tokens", "jwt", "roles", "login_limit", "session_ttl_s"});
    if (auto n = a["users"]) c.users = r.string(n, "gateway.auth.users");
    if (auto n = a["tokens"]) c.tokens = r.string(n, "gateway.auth.tokens");
    if (auto j = a["jwt"]) {
        r.check_keys(j, "gateway.auth.jwt", {"algorithm", "key", "audience", "issuer", "user_claim", "roles_claim", "leeway_s"});
        if (auto n = j["algorithm"]) c.jwt.algorithm = r.string(n, "gateway.auth.jwt.algorithm");
        if (auto n = j["key"]) c.jwt.key = r.string(n, "gateway.auth.jwt.key");
        if (auto n = j["audience"]) c.jwt.audience = r.string(n, "gateway.auth.jwt.audience");
        if (auto n = j["issuer"]) c.jwt.issuer = r.string(n, "gateway.auth.jwt.issuer");
        if (auto n = j["user_claim"]) c.jwt.user_claim = r.string(n, "gateway.auth.jwt.user_claim");
        if (auto n = j["roles_claim"]) c.jwt.roles_claim = r.string(n, "gateway.auth.jwt.roles_claim");
        if (auto n = j["leeway_s"]) c.jwt.leeway_s = static_cast<unsigned>(r.unsigned_int(n, "gateway.auth.jwt.leeway_s", 3600));
        if (c.jwt.algorithm != "HS256" && c.jwt.algorithm != "RS256" && c.jwt.algorithm != "ES256")
            r.error(j["algorithm"] ? j["algorithm"] : j, "gateway.auth.jwt.algorithm",
                    c.jwt.algorithm.empty() ? "missing (HS256, RS256 or ES256)" : "\"" + c.jwt.algorithm + "\" is not HS256, RS256 or ES256");
        if (c.jwt.key.empty()) r.error(j, "gateway.auth.jwt.key", "missing (a file: the HS256 secret, or the issuer's public key as PEM)");
        if (c.jwt.audience.empty()) r.error(j, "gateway.auth.jwt.audience", "missing (the `aud` every token must carry)");
    }
    if (auto roles = a["roles"]) {
        if (!roles.IsMap()) r.error(roles, "gateway.auth.roles", "expected a mapping of role names to lists of rules");
        for (const auto& kv : roles) {
            const std::string name = kv.first.as<std::string>();
            const std::string key = "gateway.auth.roles." + name;
            if (name.empty() || name == "_" || name.find_first_of(", \t") != std::string::npos)
                r.error(kv.first, key, "a role name has no spaces or commas (it is listed in the password file's privileges column)");
            if (!kv.second.IsSequence()) r.error(kv.second, key, "expected a list of rules {devices, members, allow}");
            std::vector<GatewayAuthConfig::Rule> rules;
            std::size_t i = 0;
            for (const auto& e : kv.second) {
                const std::string rk = key + "[" + std::to_string(i++) + "]";
                r.check_keys(e, rk, {"devices", "members", "allow"});
                GatewayAuthConfig::Rule rule;
                if (auto n = e["devices"]) rule.devices = patterns(n, r, rk + ".devices");
                if (auto n = e["members"]) rule.members = patterns(n, r, rk + ".members");
                auto allow = e["allow"];
                if (!allow) r.error(e, rk + ".allow", "missing (a list of read, write, call, lock, record)");
                for (const auto& op : r.string_list(allow, rk + ".allow")) {
                    if (op == "read") rule.read = true;
                    else if (op == "write") rule.write = true;
                    else if (op == "call") rule.call = true;
                    else if (op == "lock") rule.lock = true;
                    else if (op == "record") rule.record = true;
                    else r.error(allow, rk + ".allow", "\"" + op + "\" is not read, write, call, lock or record");
                }
                rules.push_back(std::move(rule));
            }
            c.roles.emplace_back(name, std::move(rules));
        }
    }
    if (auto l = a["login_limit"]) {
        r.check_keys(l, "gateway.auth.login_limit", {"max_failures", "window_s", "lockout_s"});
        if (auto n = l["max_failures"]) {
            c.max_failures = static_cast<unsigned>(r.unsigned_int(n, "gateway.auth.login_limit.max_failures", 1000));
            if (c.max_failures == 0) r.error(n, "gateway.auth.login_limit.max_failures", "must be at least 1");
        }
        if (auto n = l["window_s"]) c.window_s = static_cast<unsigned>(r.unsigned_int(n, "gateway.auth.login_limit.window_s", 86400));
        if (auto n = l["lockout_s"]) c.lockout_s = static_cast<unsigned>(r.unsigned_int(n, "gateway.auth.login_limit.lockout_s", 86400));
    }
    if (auto n = a["session_ttl_s"]) {
        c.session_ttl_s = static_cast<unsigned>(r.unsigned_int(n, "gateway.auth.session_ttl_s", 30u * 86400u));
        if (c.session_ttl_s < 60) r.error(n, "gateway.auth.session_ttl_s", "must be at least 60");
    }
    if (!c.enabled() && !c.roles.empty())
        r.error(a, "gateway.auth", "roles but no users, tokens or jwt: nobody could log in");
}

// An allowlist entry: "*", "scheme://" (any origin of that scheme), "scheme://host[:port]" or
// "scheme://*.domain[:port]" (http_server.cpp origin_allowed). An Origin never has a path, so an entry
// with one (or a trailing slash) could never match: refused rather than silently useless.
std::string origin_problem(const std::string& e) {
    if (e == "*") return {};
    auto sep = e.find("://");
    if (sep == std::string::npos || sep == 0) return "is not an origin (scheme://host[:port], scheme:// or *)";
    for (std::size_t i = 0; i < sep; ++i) {
        const char ch = e[i];
        if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '+' && ch != '-' && ch != '.')
            return "has a bad scheme";
    }
    auto host = std::string_view(e).substr(sep + 3);
    if (host.empty()) return {};
    if (host.find_first_of("/?#") != std::string_view::npos) return "has a path (an Origin is scheme://host[:port] only)";
    for (char ch : host)
        if (std::isspace(static_cast<unsigned char>(ch)) || ch == '@') return "has a bad host";
    std::size_t colon = std::string_view::npos;
    if (host.front() == '[') {  // IPv6 literal: [::1]:port
        auto close = host.find(']');
        if (close == std::string_view::npos) return "has a bad host";
        if (close + 1 < host.size()) {
            if (host[close + 1] != ':') return "has a bad host";
            colon = close + 1;
        }
    } else {
        colon = host.rfind(':');
    }
    if (colon != std::string_view::npos) {
        auto port = host.substr(colon + 1);
        unsigned v = 0;
        auto [p, ec] = std::from_chars(port.data(), port.data() + port.size(), v);
        if (port.empty() || ec != std::errc() || p != port.data() + port.size() || v == 0 || v > 65535)
            return "has a bad port";
        host = host.substr(0, colon);
    }
    if (host.empty() || host == "*.") return "has no host";
    return {};
}

void parse_limits(const YAML::Node& l, const Reader& r, GatewayLimitsConfig& c) {
    r.check_keys(l, "gateway.limits",
                 {"connections_per_address", "messages_per_second", "bytes_per_second", "burst_s"});
    if (auto n = l["connections_per_address"])
        c.connections_per_address = r.unsigned_int(n, "gateway.limits.connections_per_address", 1000000);
    if (auto n = l["messages_per_second"])
        c.messages_per_second = r.unsigned_int(n, "gateway.limits.messages_per_second", 100000000);
    if (auto n = l["bytes_per_second"]) {
        c.bytes_per_second = r.unsigned_int(n, "gateway.limits.bytes_per_second", std::uint64_t{1} << 40);
        if (c.bytes_per_second != 0 && c.bytes_per_second < 1024)
            r.error(n, "gateway.limits.bytes_per_second", "must be 0 (unlimited) or at least 1024");
    }
    if (auto n = l["burst_s"]) {
        c.burst_s = static_cast<unsigned>(r.unsigned_int(n, "gateway.limits.burst_s", 3600));
        if (c.burst_s == 0) r.error(n, "gateway.limits.burst_s", "must be at least 1");
    }
}

// A YAML mapping as JSON (scalars: integers, true/false, else strings), for the `record:` entries,
// whose keys are those of POST /api/recordings (record::spec_from_json checks them).
nlohmann::json yaml_to_json(const YAML::Node& n) {
    if (n.IsMap()) {
        auto o = nlohmann::json::object();
        for (const auto& kv : n) o[kv.first.as<std::string>()] = yaml_to_json(kv.second);
        return o;
    }
    if (n.IsSequence()) {
        auto a = nlohmann::json::array();
        for (const auto& x : n) a.push_back(yaml_to_json(x));
        return a;
    }
    if (n.IsNull()) return nullptr;
    const std::string& s = n.Scalar();
    std::uint64_t u = 0;
    if (auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), u); !s.empty() && ec == std::errc() && p == s.data() + s.size())
        return u;
    bool b = false;
    if (n.Tag() != "!" && YAML::convert<bool>::decode(n, b)) return b;
    return s;
}

// record: a list of recordings (docs/recording.md "Configuration"), after `recordings:` (its bounds).
void parse_record(const YAML::Node& root, const Reader& r, GatewayConfig& c) {
    auto rec = root["record"];
    if (!rec) return;
    if (!rec.IsSequence()) r.error(rec, "record", "expected a list of recordings");
    for (const auto& e : rec) {
        if (!e.IsMap()) r.error(e, "record[]", "expected a mapping");
        auto spec = record::spec_from_json(yaml_to_json(e));
        if (!spec) r.error(e, "record[]", spec.error().message);
        if (auto b = record::check_spec_bounds(*spec, c.recordings); !b) r.error(e, "record[]", b.error().message);
        c.record.push_back(std::move(*spec));
    }
}

// recordings: (docs/recording.md "Where recordings go").
void parse_recordings(const YAML::Node& n, const Reader& r, record::RecordingsSettings& s) {
    r.check_keys(n, "recordings", {"root", "max_total_bytes", "max_active", "max_queue_bytes", "keep_ended", "replay_memory_bytes"});
    if (auto v = n["root"]) {
        s.root = r.string(v, "recordings.root");
        if (s.root.empty()) r.error(v, "recordings.root", "empty (leave the key out for the default)");
    }
    if (auto v = n["max_total_bytes"]) {
        s.max_total_bytes = r.unsigned_int(v, "recordings.max_total_bytes", std::uint64_t{1} << 50);
        if (s.max_total_bytes < (1u << 20)) r.error(v, "recordings.max_total_bytes", "must be at least 1048576 (1 MiB)");
    }
    if (auto v = n["max_active"]) {
        s.max_active = r.unsigned_int(v, "recordings.max_active", 1000);
        if (s.max_active == 0) r.error(v, "recordings.max_active", "must be at least 1");
    }
    if (auto v = n["max_queue_bytes"]) {
        s.max_queue_bytes = r.unsigned_int(v, "recordings.max_queue_bytes", std::uint64_t{16} << 30);
        if (s.max_queue_bytes < 4096) r.error(v, "recordings.max_queue_bytes", "must be at least 4096");
    }
    if (auto v = n["keep_ended"]) s.keep_ended = r.unsigned_int(v, "recordings.keep_ended", 100000);
    if (auto v = n["replay_memory_bytes"]) {
        s.replay_memory_bytes = r.unsigned_int(v, "recordings.replay_memory_bytes", std::uint64_t{64} << 30);
        if (s.replay_memory_bytes < (1u << 20)) r.error(v, "recordings.replay_memory_bytes", "must be at least 1048576 (1 MiB)");
    }
}

// devices[] with `replay: FILE` (docs/recording.md "Replay").
void parse_replay_device(const YAML::Node& d, const Reader& r, GatewayConfig& c, std::set<std::string>& names) {
    r.check_keys(d, "devices[]", {"name", "replay", "speed", "loop", "paused"});
    ReplayDeviceConfig rc;
    if (!d["name"]) r.error(d, "devices[].name", "missing");
    rc.name = r.string(d["name"], "devices[].name");
    const std::string key = "devices." + rc.name;
    rc.file = r.string(d["replay"], key + ".replay");
    if (rc.file.empty()) r.error(d["replay"], key + ".replay", "empty file name");
    if (auto n = d["speed"]) {
        double v = 0;
        if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !(v > 0) || v > 1000)
            r.error(n, key + ".speed", "expected a number above 0 and at most 1000");
        rc.speed = v;
    }
    if (auto n = d["loop"]) rc.loop = r.boolean(n, key + ".loop");
    if (auto n = d["paused"]) rc.paused = r.boolean(n, key + ".paused");
    if (!names.insert(rc.name).second) r.error(d["name"], key, "duplicate device name");
    c.replays.push_back(std::move(rc));
}

GatewayConfig parse(const YAML::Node& root, const Reader& r) {
    GatewayConfig c;
    if (!root.IsDefined() || root.IsNull()) return c;
    r.check_keys(root, "", {"gateway", "demo", "devices", "discovery", "discover", "usb", "record", "recordings", "safety", "foxglove"});
    if (auto n = root["recordings"]) parse_recordings(n, r, c.recordings);
    // foxglove: (docs/foxglove.md): objects below a device's root advertised beside it; the device
    // whose clock is Foxglove's time.
    if (auto f = root["foxglove"]) {
        r.check_keys(f, "foxglove", {"objects", "clock"});
        if (auto n = f["clock"]) c.foxglove_clock = r.string(n, "foxglove.clock");
        if (auto o = f["objects"]) {
            if (!o.IsMap()) r.error(o, "foxglove.objects", "expected a map of device name to a list of object paths");
            else
                for (const auto& kv : o) {
                    const std::string device = kv.first.as<std::string>();
                    c.foxglove_objects[device] = r.string_list(kv.second, "foxglove.objects." + device);
                }
        }
    }
    if (auto g = root["gateway"]) {
        r.check_keys(g, "gateway",
                     {"listen", "port", "node_name", "node_id", "threads", "web_root", "allowed_origins", "trusted_proxies",
                      "websocket_compression", "websocket_gathered_writes", "max_message_size", "log_level", "log_format",
                      "local", "tls", "auth", "limits"});
        if (auto l = g["limits"]) parse_limits(l, r, c.limits);
        if (auto a = g["auth"]) parse_auth(a, r, c.auth);
        if (auto n = g["listen"]) c.listen = r.string(n, "gateway.listen");
        if (auto n = g["port"]) c.port = static_cast<std::uint16_t>(r.unsigned_int(n, "gateway.port", 65535));
        if (auto n = g["node_name"]) {
            c.node_name = r.string(n, "gateway.node_name");
            if (!valid_node_name(c.node_name))
                r.error(n, "gateway.node_name", "not a NodeName (letters, digits, _ . -, starting with a letter)");
        }
        if (auto n = g["node_id"]) {
            c.node_id = r.string(n, "gateway.node_id");
            if (!NodeID::parse(c.node_id)) r.error(n, "gateway.node_id", "not a NodeID (UUID)");
        }
        if (auto n = g["threads"]) c.threads = static_cast<unsigned>(r.unsigned_int(n, "gateway.threads", 256));
        if (auto n = g["web_root"]) c.web_root = r.string(n, "gateway.web_root");
        if (auto n = g["allowed_origins"]) {
            c.allowed_origins = r.string_list(n, "gateway.allowed_origins");
            for (const auto& o : c.allowed_origins)
                if (auto why = origin_problem(o); !why.empty())
                    r.error(n, "gateway.allowed_origins", "\"" + o + "\" " + why);
        }
        if (auto n = g["trusted_proxies"]) {
            c.trusted_proxies = r.string_list(n, "gateway.trusted_proxies");
            for (const auto& p : c.trusted_proxies)
                if (!http::parse_ip_network(p))
                    r.error(n, "gateway.trusted_proxies", "\"" + p + "\" is not an IP address or CIDR range (10.0.0.0/8)");
        }
        if (auto w = g["websocket_compression"]) {
            r.check_keys(w, "gateway.websocket_compression", {"enabled", "paths"});
            if (auto n = w["enabled"]) c.websocket_compression.enabled = r.boolean(n, "gateway.websocket_compression.enabled");
            if (auto n = w["paths"]) {
                c.websocket_compression.paths = r.string_list(n, "gateway.websocket_compression.paths");
                for (const auto& p : c.websocket_compression.paths)
                    if (p.empty() || p.front() != '/' || p.find_first_of("?# ") != std::string::npos)
                        r.error(n, "gateway.websocket_compression.paths", "\"" + p + "\" is not a request path (\"/…\", no query)");
            }
        }
        if (auto n = g["websocket_gathered_writes"])
            c.websocket_gathered_writes = r.boolean(n, "gateway.websocket_gathered_writes");
        if (auto n = g["max_message_size"]) {
            c.max_message_size = r.unsigned_int(n, "gateway.max_message_size", 100u * 1024u * 1024u);
            if (c.max_message_size < 16 * 1024) r.error(n, "gateway.max_message_size", "must be at least 16384");
        }
        if (auto n = g["local"]) c.local = r.boolean(n, "gateway.local");
        if (auto t = g["tls"]) {
            r.check_keys(t, "gateway.tls",
                         {"certificate", "private_key", "client_ca", "node_certificate", "node_private_key", "required"});
            if (auto n = t["required"]) c.tls.required = r.boolean(n, "gateway.tls.required");
            if (auto n = t["certificate"]) c.tls.certificate = r.string(n, "gateway.tls.certificate");
            if (auto n = t["private_key"]) c.tls.private_key = r.string(n, "gateway.tls.private_key");
            if (auto n = t["client_ca"]) c.tls.client_ca = r.string(n, "gateway.tls.client_ca");
            if (auto n = t["node_certificate"]) c.tls.node_certificate = r.string(n, "gateway.tls.node_certificate");
            if (auto n = t["node_private_key"]) c.tls.node_private_key = r.string(n, "gateway.tls.node_private_key");
            if (c.tls.certificate.empty()) r.error(t, "gateway.tls.certificate", "missing (TLS needs a certificate and its private key)");
            if (c.tls.private_key.empty()) r.error(t, "gateway.tls.private_key", "missing (the certificate's key)");
            if (c.tls.node_certificate.empty() != c.tls.node_private_key.empty())
                r.error(t, "gateway.tls", "node_certificate and node_private_key go together");
        }
        if (auto n = g["log_level"]) {
            c.log_level = r.string(n, "gateway.log_level");
            if (!kLogLevels.count(c.log_level)) r.error(n, "gateway.log_level", "unknown level \"" + c.log_level + "\"");
        }
        if (auto n = g["log_format"]) {
            c.log_format = r.string(n, "gateway.log_format");
            if (!kLogFormats.count(c.log_format))
                r.error(n, "gateway.log_format", "unknown format \"" + c.log_format + "\" (text or json)");
        }
    }
    if (auto d = root["demo"]) {
        r.check_keys(d, "demo", {"enabled", "port"});
        if (auto n = d["enabled"]) c.demo = r.boolean(n, "demo.enabled");
        if (auto n = d["port"]) c.demo_port = static_cast<std::uint16_t>(r.unsigned_int(n, "demo.port", 65535));
    }
    if (auto devs = root["devices"]) {
        if (!devs.IsSequence()) r.error(devs, "devices", "expected a list of devices");
        std::set<std::string> names;
        for (const auto& d : devs) {
            if (d.IsMap() && d["replay"]) {
                parse_replay_device(d, r, c, names);
                continue;
            }
            r.check_keys(d, "devices[]", {"name", "url", "username", "password", "required", "backoff_max_ms", "tls_ca",
                                          "tls_certificate", "tls_private_key", "auth", "max_passthrough_sessions",
                                          "json_api_requires_device_login", "replay", "safety"});
            gateway::DeviceConfig dc;
            if (!d["name"]) r.error(d, "devices[].name", "missing");
            if (!d["url"]) r.error(d, "devices[].url", "missing");
            dc.name = r.string(d["name"], "devices[].name");
            const std::string key = "devices." + dc.name;
            dc.url = r.string(d["url"], key + ".url");
            auto url = parse_connection_url(dc.url);
            if (!url) r.error(d["url"], key + ".url", url.error().message);
            if (url->service.empty()) r.error(d["url"], key + ".url", "names no service (add ?service=NAME)");
            if (auto n = d["username"]) dc.username = r.string(n, key + ".username");
            if (auto n = d["password"]) dc.password = r.string(n, key + ".password");
            if (auto n = d["required"]) dc.required = r.boolean(n, key + ".required");
            if (auto n = d["auth"]) {
                const std::string mode = r.string(n, key + ".auth");
                if (mode == "passthrough")
                    dc.auth = gateway::DeviceAuth::passthrough;
                else if (mode == "shared" || mode == "gateway")  // "gateway": the gateway's logins apply (issue 10's name)
                    dc.auth = gateway::DeviceAuth::shared;
                else
                    r.error(n, key + ".auth", "expected shared (alias gateway) or passthrough, got \"" + mode + "\"");
            }
            if (auto n = d["max_passthrough_sessions"]) {
                dc.max_passthrough_sessions = r.unsigned_int(n, key + ".max_passthrough_sessions", 100000);
                if (dc.max_passthrough_sessions == 0) r.error(n, key + ".max_passthrough_sessions", "must be at least 1");
            }
            if (auto n = d["json_api_requires_device_login"]) {
                dc.json_api_requires_device_login = r.boolean(n, key + ".json_api_requires_device_login");
                if (dc.json_api_requires_device_login && dc.auth != gateway::DeviceAuth::passthrough)
                    r.error(n, key + ".json_api_requires_device_login",
                            "needs auth: passthrough (only a passthrough device has logins of its own for JSON API clients)");
            }
            if (auto n = d["tls_ca"]) dc.tls_ca = r.string(n, key + ".tls_ca");
            if (auto n = d["tls_certificate"]) dc.tls_certificate = r.string(n, key + ".tls_certificate");
            if (auto n = d["tls_private_key"]) dc.tls_private_key = r.string(n, key + ".tls_private_key");
            if (dc.tls_certificate.empty() != dc.tls_private_key.empty())
                r.error(d, key, "tls_certificate and tls_private_key go together");
            if (auto n = d["backoff_max_ms"])
                dc.backoff_max = std::chrono::milliseconds(r.unsigned_int(n, key + ".backoff_max_ms", 3600000));
            if (!names.insert(dc.name).second) r.error(d["name"], key, "duplicate device name");
            if (auto n = d["safety"]) parse_device_safety(n, r, key + ".safety", c, dc.name);
            c.devices.push_back(std::move(dc));
        }
    }
    parse_discovery(root, r, c);
    parse_usb(root, r, c);
    parse_record(root, r, c);
    parse_safety(root, r, c);
    return c;
}

}  // namespace

gateway::MotionSafety SafetyConfig::for_device(std::string_view name) const {
    gateway::MotionSafety m;
    m.hold_to_run_max = hold_to_run_max;
    m.standard_robot = standard_robot;
    if (auto it = overrides.find(std::string(name)); it != overrides.end()) {
        if (it->second.hold_to_run_max) m.hold_to_run_max = *it->second.hold_to_run_max;
        if (it->second.standard_robot) m.standard_robot = *it->second.standard_robot;
    }
    for (const auto& h : hold_to_run)
        if (h.device == name) m.hold_to_run.push_back(h.rule);
    for (const auto& x : motions)
        if (x.device == name) m.motions.push_back(x.rule);
    for (const auto& x : streams)
        if (x.device == name) m.streams.push_back(x.rule);
    for (const auto& x : stops)
        if (x.device == name) m.stops.push_back(x.rule);
    return m;
}

bool usb_wanted(const GatewayConfig& config) {
    switch (config.usb.enabled) {
        case UsbSettings::Mode::on: return true;
        case UsbSettings::Mode::off: return false;
        case UsbSettings::Mode::automatic: return names_usb(config, nullptr);
    }
    return false;
}

Result<GatewayConfig> parse_gateway_config(std::string_view yaml_text, std::string_view source) {
    Reader reader(source);
    try {
        YAML::Node root = YAML::Load(std::string(yaml_text));
        return parse(root, reader);
    } catch (const ConfigError& e) {
        return fail(MessageErrorType::InvalidConfiguration, e.text);
    } catch (const YAML::Exception& e) {
        return fail(MessageErrorType::InvalidConfiguration,
                    std::string(source) + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
    }
}

Result<GatewayConfig> load_gateway_config(const std::string& path) {
    std::ifstream f(path);
    if (!f) return fail(MessageErrorType::InvalidConfiguration, path + ": cannot read the configuration file");
    std::stringstream ss;
    ss << f.rdbuf();
    return parse_gateway_config(ss.str(), path);
}

namespace {

// Flags that take a value, with their official RR spellings mapped to ours.
const std::set<std::string> kValueFlags{"--config",      "--port",       "--listen",    "--web-root",      "--recordings-root",
                                        "--allow-origin", "--device",     "--replay",    "--demo-port", "--threads", "--trusted-proxy",
                                        "--log-level",   "--log-format", "--robotraconteur-tcp-port", "--robotraconteur-nodename",
                                        "--robotraconteur-nodeid", "--robotraconteur-log-level", "--tls-certificate",
                                        "--tls-private-key", "--tls-client-ca"};
const std::set<std::string> kBoolFlags{"--no-demo",     "--no-local", "--discovery", "--no-discovery",
                                       "--check",       "--help",     "-h",          "--tls-required"};

}  // namespace

Result<CommandLine> parse_command_line(int argc, const char* const* argv) {
    CommandLine cmd;
    for (int i = 1; i < argc; ++i) {
        std::string arg = argv[i];
        std::string name = arg, value;
        bool has_value = false;
        if (auto eq = arg.find('='); arg.rfind("--", 0) == 0 && eq != std::string::npos) {
            name = arg.substr(0, eq);
            value = arg.substr(eq + 1);
            has_value = true;
        }
        if (kBoolFlags.count(name)) {
            if (has_value) return fail(MessageErrorType::InvalidConfiguration, name + " takes no value");
            if (name == "--help" || name == "-h") cmd.help = true;
            else if (name == "--check") cmd.check_only = true;
            else cmd.overrides.push_back(name);
            continue;
        }
        if (kValueFlags.count(name)) {
            if (!has_value) {
                if (i + 1 >= argc) return fail(MessageErrorType::InvalidConfiguration, name + " needs a value");
                value = argv[++i];
            }
            if (name == "--config")
                cmd.config_file = value;
            else
                cmd.overrides.push_back(name + "=" + value);
            continue;
        }
        // Other --robotraconteur-* options of the official library do not apply to the gateway.
        if (name.rfind("--robotraconteur-", 0) == 0)
            return fail(MessageErrorType::InvalidConfiguration, "flag " + name + " is not supported by rr-gateway");
        return fail(MessageErrorType::InvalidConfiguration, "unknown flag \"" + arg + "\" (see --help)");
    }
    return cmd;
}

Result<void> apply_overrides(GatewayConfig& c, const CommandLine& cmd) {
    auto number = [](const std::string& flag, const std::string& v, std::uint64_t max) -> Result<std::uint64_t> {
        std::uint64_t n = 0;
        auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), n);
        if (v.empty() || ec != std::errc() || p != v.data() + v.size() || n > max)
            return fail(MessageErrorType::InvalidConfiguration, flag + ": expected an integer up to " + std::to_string(max));
        return n;
    };
    for (const auto& o : cmd.overrides) {
        auto eq = o.find('=');
        std::string flag = o.substr(0, eq);
        std::string v = eq == std::string::npos ? std::string() : o.substr(eq + 1);
        if (flag == "--port" || flag == "--robotraconteur-tcp-port") {
            auto n = number(flag, v, 65535);
            if (!n) return n.take_error();
            c.port = static_cast<std::uint16_t>(*n);
        } else if (flag == "--demo-port") {
            auto n = number(flag, v, 65535);
            if (!n) return n.take_error();
            c.demo_port = static_cast<std::uint16_t>(*n);
        } else if (flag == "--threads") {
            auto n = number(flag, v, 256);
            if (!n) return n.take_error();
            c.threads = static_cast<unsigned>(*n);
        } else if (flag == "--listen") {
            c.listen = v;
        } else if (flag == "--web-root") {
            c.web_root = v;
        } else if (flag == "--recordings-root") {
            if (v.empty()) return fail(MessageErrorType::InvalidConfiguration, flag + ": expected a folder");
            c.recordings.root = v;
        } else if (flag == "--allow-origin") {
            if (auto why = origin_problem(v); !why.empty())
                return fail(MessageErrorType::InvalidConfiguration, flag + ": \"" + v + "\" " + why);
            c.allowed_origins.push_back(v);
        } else if (flag == "--trusted-proxy") {
            if (!http::parse_ip_network(v))
                return fail(MessageErrorType::InvalidConfiguration, flag + ": \"" + v + "\" is not an IP address or CIDR range");
            c.trusted_proxies.push_back(v);
        } else if (flag == "--no-demo") {
            c.demo = false;
        } else if (flag == "--no-local") {
            c.local = false;
        } else if (flag == "--discovery") {
            c.discovery.enabled = true;
        } else if (flag == "--no-discovery") {
            c.discovery.enabled = false;
        } else if (flag == "--tls-certificate") {
            c.tls.certificate = v;
        } else if (flag == "--tls-private-key") {
            c.tls.private_key = v;
        } else if (flag == "--tls-client-ca") {
            c.tls.client_ca = v;
        } else if (flag == "--tls-required") {
            c.tls.required = true;
        } else if (flag == "--robotraconteur-nodename") {
            c.node_name = v;
        } else if (flag == "--robotraconteur-nodeid") {
            if (!NodeID::parse(v)) return fail(MessageErrorType::InvalidConfiguration, flag + ": not a NodeID");
            c.node_id = v;
        } else if (flag == "--log-level" || flag == "--robotraconteur-log-level") {
            std::string level = v;
            for (auto& ch : level) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
            if (!kLogLevels.count(level)) return fail(MessageErrorType::InvalidConfiguration, flag + ": unknown level \"" + v + "\"");
            c.log_level = level;
        } else if (flag == "--log-format") {
            if (!kLogFormats.count(v)) return fail(MessageErrorType::InvalidConfiguration, flag + ": unknown format \"" + v + "\" (text or json)");
            c.log_format = v;
        } else if (flag == "--device") {
            auto e2 = v.find('=');
            if (e2 == std::string::npos)
                return fail(MessageErrorType::InvalidConfiguration, "--device: expected NAME=URL");
            gateway::DeviceConfig d;
            d.name = v.substr(0, e2);
            d.url = v.substr(e2 + 1);
            auto url = parse_connection_url(d.url);
            if (!url) return fail(MessageErrorType::InvalidConfiguration, "--device " + d.name + ": " + url.error().message);
            if (url->service.empty())
                return fail(MessageErrorType::InvalidConfiguration, "--device " + d.name + ": URL names no service");
            std::erase_if(c.devices, [&](const gateway::DeviceConfig& x) { return x.name == d.name; });
            c.devices.push_back(std::move(d));
        } else if (flag == "--replay") {
            // [NAME=]FILE: NAME defaults to the recorded device's name.
            ReplayDeviceConfig rc;
            auto e2 = v.find('=');
            if (e2 != std::string::npos && v.find('/') > e2) {
                rc.name = v.substr(0, e2);
                rc.file = v.substr(e2 + 1);
            } else {
                rc.file = v;
            }
            if (rc.file.empty()) return fail(MessageErrorType::InvalidConfiguration, "--replay: expected [NAME=]FILE");
            c.replays.push_back(std::move(rc));
        }
    }
    std::string problem;
    validate(c, [&](const std::string& key, const std::string& what) {
        if (problem.empty()) problem = key + ": " + what;
    });
    if (!problem.empty()) return fail(MessageErrorType::InvalidConfiguration, problem);
    return {};
}

std::string usage_text() {
    return R"(Usage: rr-gateway [--config FILE] [options]

Robot Raconteur gateway: devices re-exposed over WebSocket and HTTP.
With no configuration it starts two demo devices (experimental.create, experimental.createwebcam),
listens on port 8080 on every address (IPv4 and IPv6) and announces itself on the local network, as
an official Robot Raconteur server node does, so official clients find it by type and NodeName.

Options (override the configuration file):
  --config FILE              YAML configuration (docs/gateway-config.md)
  --port N                   RR + HTTP + WebSocket port (default 8080)
  --listen ADDR              listen address (default ::, IPv4 and IPv6 on one socket;
                             0.0.0.0: IPv4 only; 127.0.0.1: this computer only)
  --web-root DIR             dashboard files to serve
  --allow-origin ORIGIN      allow a browser Origin (repeatable)
  --trusted-proxy ADDR[/N]   believe X-Forwarded-For/-Proto from this proxy (repeatable)
  --device NAME=URL          add a device, e.g. reynard=rr+tcp://localhost:29200/?service=reynard
                             or cam=rr+local:///?nodename=camera.driver&service=cam
  --replay [NAME=]FILE       serve an MCAP recording as a device (docs/recording.md); NAME
                             defaults to the recorded device's name
  --recordings-root DIR      the folder every recording goes below (recordings.root; default:
                             $STATE_DIRECTORY/recordings under systemd, else ./recordings)
  --no-demo                  do not start the demo devices
  --no-local                 do not serve rr+local (the gateway's NodeName on this computer)
  --no-discovery             no node discovery: do not announce the gateway (nor its demo node),
                             answer or send discovery requests, or list nodes (on by default, as
                             on an official node; docs/discovery.md)
  --discovery                node discovery on (the default; overrides discovery.enabled: false)
  --tls-certificate FILE     serve HTTPS, WSS and rrs+tcp on the same port with this PEM
                             certificate chain (leaf first) ...
  --tls-private-key FILE     ... and its private key (docs/security.md)
  --tls-client-ca FILE       require client certificates issued by these CAs (mTLS)
  --tls-required             refuse plain RR and plain HTTP on the port (TLS only)
  --demo-port N              RR port of the demo devices' node (default: ephemeral)
  --threads N                worker threads (default: cores)
  --log-level LEVEL          trace, debug, info, warning, error
  --log-format FORMAT        text (default) or json: one JSON object per line
  --check                    validate the configuration and exit
  --robotraconteur-tcp-port=N, --robotraconteur-nodename=NAME,
  --robotraconteur-nodeid=ID, --robotraconteur-log-level=LEVEL
                             the official library's flags, where they apply
)";
}

}  // namespace rr::server::app
