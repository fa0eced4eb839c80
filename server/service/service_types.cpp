#include "server/service/service_types.hpp"

#include <algorithm>

#include "robdef/builtin/service_index.hpp"
#include "robdef/parser.hpp"
#include "robdef/verifier.hpp"

namespace rr::server {

namespace {

std::pair<std::string_view, std::string_view> split_qualified(std::string_view name) {
    auto dot = name.rfind('.');
    if (dot == std::string_view::npos) return {std::string_view(), name};
    return {name.substr(0, dot), name.substr(dot + 1)};
}

}  // namespace

Result<std::shared_ptr<const ServiceTypes>> ServiceTypes::create(std::vector<std::string> texts) {
    if (texts.empty()) return fail(MessageErrorType::InvalidArgument, "no service definition given");
    std::shared_ptr<ServiceTypes> types(new ServiceTypes());
    std::string errors;
    for (std::size_t i = 0; i < texts.size(); ++i) {
        const std::string file = "definition " + std::to_string(i + 1);
        auto parsed = robdef::parse_service_definition(texts[i], file);
        if (!parsed) {
            if (!errors.empty()) errors += '\n';
            errors += parsed.error().message;
            continue;
        }
        std::string name = parsed->definition.name;
        // The set starts with the built-in service index; a node's own index service gives it again.
        const bool replaces_builtin = name == robdef::kServiceIndexServiceName && !types->text(name);
        if (types->set_.find_service(name) && !replaces_builtin) {
            if (!errors.empty()) errors += '\n';
            errors += file + ": error: service definition " + name + " is defined more than once";
            continue;
        }
        types->set_.add(std::move(parsed->definition));
        types->texts_.push_back(Text{std::move(name), std::move(texts[i])});
    }
    if (!errors.empty()) return fail(MessageErrorType::ServiceDefinitionError, errors);
    auto diagnostics = types->set_.verify();
    for (const auto& d : diagnostics) {
        if (!d.is_error()) continue;
        if (!errors.empty()) errors += '\n';
        errors += robdef::format_diagnostic(d);
    }
    if (!errors.empty()) return fail(MessageErrorType::ServiceDefinitionError, errors);
    return std::shared_ptr<const ServiceTypes>(std::move(types));
}

const robdef::ServiceEntryDefinition* ServiceTypes::find_object(std::string_view qualified_name) const noexcept {
    auto [svc, name] = split_qualified(qualified_name);
    if (svc.empty()) return nullptr;
    const auto* def = set_.find_service(svc);
    if (!def) return nullptr;
    for (const auto& o : def->objects)
        if (o.name == name) return &o;
    return nullptr;
}

std::optional<std::string> ServiceTypes::text(std::string_view service_name) const {
    for (const auto& t : texts_)
        if (t.service_name == service_name) return t.text;
    return std::nullopt;
}

std::vector<std::string> ServiceTypes::texts_for(std::string_view service_name) const {
    std::vector<std::string> names{std::string(service_name)};
    for (std::size_t i = 0; i < names.size(); ++i) {
        const auto* def = set_.find_service(names[i]);
        if (!def) continue;
        for (const auto& imp : def->imports)
            if (std::find(names.begin(), names.end(), imp) == names.end()) names.push_back(imp);
    }
    std::vector<std::string> out;
    for (const auto& n : names)
        if (auto t = text(n)) out.push_back(std::move(*t));
    return out;
}

std::vector<std::string> ServiceTypes::implements_of(std::string_view type) const {
    std::vector<std::string> out;
    const auto* obj = find_object(type);
    if (!obj) return out;
    auto [svc, name] = split_qualified(type);
    for (const auto& imp : obj->implements) {
        auto ref = set_.find(imp, svc);
        if (ref && ref.entry && ref.entry->kind == robdef::EntryKind::object)
            out.push_back(ref.service->name + "." + ref.entry->name);
    }
    return out;
}

bool ServiceTypes::object_is_a(std::string_view type, std::string_view base) const {
    std::vector<std::string> todo{std::string(type)};
    for (std::size_t i = 0; i < todo.size() && i < 256; ++i) {
        if (todo[i] == base) return true;
        for (auto& b : implements_of(todo[i]))
            if (std::find(todo.begin(), todo.end(), b) == todo.end()) todo.push_back(std::move(b));
    }
    return false;
}

RRError ServiceTypes::user_error(std::string_view exception, std::string message, std::string_view context_service) const {
    auto [svc, name] = split_qualified(exception);
    if (svc.empty()) svc = context_service;
    if (const auto* def = set_.find_service(svc); def && def->find_exception(name)) {
        RRError e;
        e.type = MessageErrorType::RemoteError;
        e.name = std::string(svc) + "." + std::string(name);
        e.message = std::move(message);
        return e;
    }
    return make_error(MessageErrorType::InternalError,
                      "service raised undeclared exception \"" + std::string(exception) + "\": " + message);
}

}  // namespace rr::server
