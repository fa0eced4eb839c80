#include "server/cli/cli_commands.hpp"

#include <algorithm>

#include "robdef/builtin/service_index.hpp"
#include "server/cli/cli_discover.hpp"
#include "server/cli/cli_record.hpp"
#include "server/cli/cli_target.hpp"
#include "server/cli/cli_watch.hpp"

namespace rr::cli {

namespace {

using robdef::MemberKind;

Failure rr_failure(RRError e) { return Failure{ExitCode::rr_error, std::move(e)}; }
Failure rr_failure(MessageErrorType t, std::string message) { return rr_failure(make_error(t, std::move(message))); }

std::string params_text(const std::vector<robdef::TypeDefinition>& params) {
    std::string s;
    for (const auto& p : params) s += (s.empty() ? "" : ", ") + p.to_string() + " " + p.name;
    return s;
}

// The TYPE column of `rr info`: the value type, or RET(PARAMS) for functions and callbacks.
std::string member_type_text(const robdef::MemberDefinition& m) {
    switch (m.kind) {
        case MemberKind::function:
        case MemberKind::callback: return m.type.to_string() + "(" + params_text(m.parameters) + ")";
        case MemberKind::event: return "(" + params_text(m.parameters) + ")";
        default: return m.type.to_string();
    }
}

// The name on a definition's `service` line (comments may come first).
std::string service_name_of(const std::string& text) {
    std::size_t pos = 0;
    while (pos < text.size()) {
        auto end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        auto line = text.substr(pos, end - pos);
        auto start = line.find_first_not_of(" \t");
        if (start != std::string::npos && line.compare(start, 8, "service ") == 0) {
            auto name = line.substr(start + 8);
            name.erase(name.find_last_not_of(" \t\r") + 1);
            return name;
        }
        pos = end + 1;
    }
    return "?";
}

struct ObjectListing {
    std::string type;
    std::vector<std::string> implements;
    std::vector<robdef::MemberDefinition> members;
};

std::optional<Failure> print_members(Target& t, std::ostream& out) {
    const std::string path = t.object.path();
    auto listing = t.client->query<ObjectListing>([path](ClientContext& ctx, MonoTime) -> Result<ObjectListing> {
        auto ref = ctx.object(path);
        if (!ref) return fail(MessageErrorType::ObjectNotFound, "object " + path + " not known");
        auto found = ctx.definitions().find(ref->type);
        if (!found || !found.entry) return fail(MessageErrorType::ServiceDefinitionError, "no definition of " + ref->type);
        return ObjectListing{ref->type, ref->implements, found.entry->members};
    });
    if (!listing) return rr_failure(listing.error());
    out << "== object " << path << ": " << listing->type << " ==\n";
    for (const auto& i : listing->implements) out << "implements " << i << "\n";
    std::size_t w = 4;
    for (const auto& m : listing->members) w = std::max(w, m.name.size());
    for (const auto& m : listing->members) {
        std::string kind(robdef::member_kind_keyword(m.kind));
        std::string line = kind + std::string(10 - std::min<std::size_t>(kind.size(), 9), ' ') + m.name +
                           std::string(w + 2 - m.name.size(), ' ') + member_type_text(m);
        for (const auto& mod : m.modifiers) line += " [" + mod + "]";
        out << line << "\n";
    }
    return std::nullopt;
}

// `rr info` on a URL without service=: the node's RobotRaconteurServiceIndex.GetLocalNodeServices().
std::optional<Failure> print_node_services(Target& t, std::ostream& out) {
    auto m = member_info(t.object, "GetLocalNodeServices");
    if (!m) return rr_failure(m.error());
    auto r = t.object.call("GetLocalNodeServices");
    if (!r) return rr_failure(r.error());
    auto j = to_json(*t.client, *r, m->def.type, m->service);
    if (!j) return rr_failure(j.error());
    out << "== services of node " << t.client->remote_node_id().to_string() << " ==\n";
    if (!j->is_object()) return std::nullopt;
    for (const auto& [key, info] : j->items()) {
        if (!info.is_object()) continue;
        std::string url;
        if (auto u = info.find("ConnectionURL"); u != info.end() && u->is_object() && !u->empty())
            url = u->begin()->is_string() ? u->begin()->get<std::string>() : "";
        out << info.value("Name", "") << "  " << info.value("RootObjectType", "") << "  " << url << "\n";
    }
    return std::nullopt;
}

std::optional<Failure> run_info(Target& t, bool node_index, std::ostream& out) {
    if (node_index) {
        if (auto f = print_node_services(t, out)) return f;
        out << "\n";
    }
    for (const auto& text : t.client->info().service_definitions) {
        out << "== service definition: " << service_name_of(text) << " ==\n" << text;
        if (!text.empty() && text.back() != '\n') out << "\n";
        out << "\n";
    }
    return print_members(t, out);
}

std::optional<Failure> run_get(const CommandLine& cl, Target& t, std::ostream& out) {
    const std::string& name = *cl.member;
    auto m = member_info(t.object, name);
    if (!m) return rr_failure(m.error());
    Result<Value> v = fail(MessageErrorType::InvalidOperation, "");
    switch (m->def.kind) {
        case MemberKind::property: v = t.object.get(name); break;
        case MemberKind::wire: {
            auto w = t.object.peek_in_value(name);
            if (!w) return rr_failure(w.error());
            v = std::move(w->value);
            break;
        }
        case MemberKind::memory: {
            if (m->def.type.array == robdef::ArrayKind::multidimarray) {
                auto dims = t.object.memory_dimensions(name);
                if (!dims) return rr_failure(dims.error());
                v = t.object.memory_read(name, std::vector<std::uint64_t>(dims->size(), 0), *dims);
            } else {
                auto len = t.object.memory_length(name);
                if (!len) return rr_failure(len.error());
                v = t.object.memory_read(name, 0, *len);
            }
            break;
        }
        default:
            return rr_failure(MessageErrorType::InvalidOperation,
                              name + " is " + robdef::with_article(robdef::member_kind_keyword(m->def.kind)) +
                                  "; rr get reads properties, wires (InValue) and memories");
    }
    if (!v) return rr_failure(v.error());
    auto j = to_json(*t.client, *v, m->def.type, m->service);
    if (!j) return rr_failure(j.error());
    out << json_line(*j) << "\n";
    return std::nullopt;
}

std::optional<Failure> run_set(const CommandLine& cl, Target& t, const nlohmann::json& json) {
    const std::string& name = *cl.member;
    auto m = member_info(t.object, name);
    if (!m) return rr_failure(m.error());
    if (m->def.kind != MemberKind::property && m->def.kind != MemberKind::wire)
        return rr_failure(MessageErrorType::InvalidOperation,
                          name + " is " + robdef::with_article(robdef::member_kind_keyword(m->def.kind)) +
                              "; rr set writes properties and wires (OutValue)");
    auto v = from_json(*t.client, json, m->def.type, m->service);
    if (!v) return rr_failure(v.error());
    auto r = m->def.kind == MemberKind::property ? t.object.set(name, std::move(*v))
                                                 : t.object.poke_out_value(name, std::move(*v));
    if (!r) return rr_failure(r.error());
    return std::nullopt;
}

std::optional<Failure> run_call(const CommandLine& cl, Target& t, const std::vector<nlohmann::json>& json,
                                std::ostream& out) {
    const std::string& name = *cl.member;
    auto m = member_info(t.object, name);
    if (!m) return rr_failure(m.error());
    if (m->def.kind != MemberKind::function)
        return rr_failure(MessageErrorType::InvalidOperation,
                          name + " is " + robdef::with_article(robdef::member_kind_keyword(m->def.kind)) + ", not a function");
    const auto& params = m->def.parameters;
    const bool gen_param = !params.empty() && params.back().container == robdef::ContainerKind::generator;
    if (gen_param)
        return rr_failure(MessageErrorType::InvalidOperation,
                          name + " takes a generator parameter, which rr call cannot supply");
    if (json.size() != params.size())
        return rr_failure(MessageErrorType::InvalidArgument,
                          name + " takes " + std::to_string(params.size()) + " argument(s) (" + params_text(params) +
                              "), " + std::to_string(json.size()) + " given");
    std::vector<Value> args;
    for (std::size_t i = 0; i < params.size(); ++i) {
        auto v = from_json(*t.client, json[i], params[i], m->service);
        if (!v) {
            RRError e = v.error();
            e.message = "argument " + std::to_string(i + 1) + " (" + params[i].name + "): " + e.message;
            return rr_failure(std::move(e));
        }
        args.push_back(std::move(*v));
    }
    if (m->def.is_generator()) {
        auto g = t.object.generator(name, std::move(args));
        if (!g) return rr_failure(g.error());
        auto item_type = m->def.type;
        item_type.container = robdef::ContainerKind::none;
        for (;;) {
            auto v = g->next();
            if (!v) {
                if (v.error().type == MessageErrorType::StopIteration) return std::nullopt;
                return rr_failure(v.error());
            }
            auto j = to_json(*t.client, *v, item_type, m->service);
            if (!j) return rr_failure(j.error());
            out << json_line(*j) << std::endl;
        }
    }
    auto r = t.object.call(name, std::move(args));
    if (!r) return rr_failure(r.error());
    if (m->def.type.is_void()) return std::nullopt;
    auto j = to_json(*t.client, *r, m->def.type, m->service);
    if (!j) return rr_failure(j.error());
    out << json_line(*j) << "\n";
    return std::nullopt;
}

}  // namespace

void print_error(std::ostream& err, const RRError& e) {
    std::string name = e.name.empty() ? std::string(error_name(e.type)) : e.name;
    err << "rr: " << name << ": " << e.message << std::endl;
}

ExitCode run_command(const CommandLine& cl, std::ostream& out, std::ostream& err, const std::atomic<bool>& stop) {
    if (cl.kind == CommandKind::discover) return run_discover(cl, out, err);
    if (cl.kind == CommandKind::record) return run_record(cl, out, err, stop);
    if (cl.kind == CommandKind::replay) return run_replay(cl, out, err, stop);
    // Command-line JSON first: a typo must not need a connection to be reported.
    std::vector<nlohmann::json> json;
    for (std::size_t i = 0; i < cl.values.size(); ++i) {
        auto j = parse_json_argument(cl.values[i], cl.kind == CommandKind::set ? "the value" : "argument " + std::to_string(i + 1));
        if (!j) {
            print_error(err, j.error());
            return ExitCode::usage_error;
        }
        json.push_back(std::move(*j));
    }
    auto parsed = parse_connection_url(cl.url);
    if (!parsed) {
        print_error(err, parsed.error());
        return ExitCode::usage_error;
    }
    // info without service=: the node's service index, as discovery does (wire.md §11.2).
    const bool node_index = cl.kind == CommandKind::info && parsed->service.empty();
    if (parsed->service.empty() && !node_index) {
        print_error(err, make_error(MessageErrorType::InvalidArgument, "the URL names no service (add ?service=NAME)"));
        return ExitCode::usage_error;
    }
    // rr+tcp:///?nodename=NAME (no host): the node's URLs from discovery, tried in turn (docs/discovery.md).
    std::vector<std::string> candidates{cl.url};
    if (needs_discovery(*parsed)) {
        auto found = resolve_through_discovery(*parsed, std::min(cl.timeout_s, 10.0), cl.interfaces);
        if (!found) {
            print_error(err, found.error());
            return ExitCode::connect_failure;
        }
        candidates = std::move(*found);
    }

    auto target = std::make_unique<Target>();
    std::optional<Failure> f;
    for (const auto& candidate : candidates) {
        auto url = url_with_service(candidate, node_index ? std::string(robdef::kServiceIndexServiceName) : "");
        if (!url) {
            print_error(err, url.error());
            return ExitCode::usage_error;
        }
        target = std::make_unique<Target>();
        f = connect_target(cl, *url, *target);
        if (!f || f->code != ExitCode::connect_failure) break;
    }
    Target& t = *target;
    if (!f) {
        switch (cl.kind) {
            case CommandKind::info: f = run_info(t, node_index, out); break;
            case CommandKind::get: f = run_get(cl, t, out); break;
            case CommandKind::set: f = run_set(cl, t, json.at(0)); break;
            case CommandKind::call: f = run_call(cl, t, json, out); break;
            case CommandKind::watch: f = run_watch(cl, t, out, stop); break;
            case CommandKind::discover:  // handled above
            case CommandKind::record:
            case CommandKind::replay:
            case CommandKind::help: break;
        }
    }
    out.flush();
    if (!f) return ExitCode::ok;
    print_error(err, f->error);
    return f->code;
}

}  // namespace rr::cli
