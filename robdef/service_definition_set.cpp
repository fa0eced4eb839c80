#include "robdef/service_definition_set.hpp"

#include <cstdlib>

#include "robdef/builtin/service_index.hpp"
#include "robdef/parser.hpp"
#include "robdef/verifier.hpp"

namespace rr::robdef {
namespace {

NamedTypeRef find_in(const ServiceDefinition& s, std::string_view name) {
    if (const auto* e = s.find_entry(name)) return NamedTypeRef{&s, e, nullptr};
    if (const auto* e = s.find_enum(name)) return NamedTypeRef{&s, nullptr, e};
    return {};
}

NamedTypeKind kind_of(const NamedTypeRef& r) {
    if (r.enumeration) return NamedTypeKind::enumeration;
    switch (r.entry->kind) {
        case EntryKind::structure: return NamedTypeKind::structure;
        case EntryKind::pod: return NamedTypeKind::pod;
        case EntryKind::namedarray: return NamedTypeKind::namedarray;
        case EntryKind::object: return NamedTypeKind::object;
    }
    return NamedTypeKind::unresolved;
}

void resolve_type(TypeDefinition& t, const std::string& service, const TypeLookup& lookup) {
    if (t.base != DataTypes::namedtype_t) return;
    NamedTypeRef r = lookup.find(t.type_name, service);
    if (!r) {
        t.named_kind = NamedTypeKind::unresolved;
        t.qualified_name.clear();
        return;
    }
    t.named_kind = kind_of(r);
    t.qualified_name = r.service->name + "." + (r.enumeration ? r.enumeration->name : r.entry->name);
}

}  // namespace

void resolve_named_types(ServiceDefinition& def, const TypeLookup& lookup) {
    for (auto* list : {&def.structures, &def.pods, &def.namedarrays, &def.objects})
        for (auto& e : *list)
            for (auto& m : e.members) {
                resolve_type(m.type, def.name, lookup);
                for (auto& p : m.parameters) resolve_type(p, def.name, lookup);
            }
}

ServiceDefinitionSet::ServiceDefinitionSet() {
    auto r = parse_service_definition(service_index_robdef(), "RobotRaconteurServiceIndex.robdef");
    if (!r) std::abort();  // the embedded text is a constant of this program
    add(std::move(r->definition));
}

Result<std::vector<Diagnostic>> ServiceDefinitionSet::add_text(std::string_view text, std::string_view file_name) {
    auto r = parse_service_definition(text, file_name);
    if (!r) return r.take_error();
    add(std::move(r->definition));
    return std::move(r->warnings);
}

const ServiceDefinition& ServiceDefinitionSet::add(ServiceDefinition def) {
    ServiceDefinition* slot = nullptr;
    for (auto& d : defs_)
        if (d->name == def.name) {
            *d = std::move(def);
            slot = d.get();
            break;
        }
    if (!slot) {
        defs_.push_back(std::make_unique<ServiceDefinition>(std::move(def)));
        slot = defs_.back().get();
    }
    resolve_all();
    return *slot;
}

void ServiceDefinitionSet::resolve_all() {
    for (auto& d : defs_) resolve_named_types(*d, *this);
}

std::vector<Diagnostic> ServiceDefinitionSet::verify() const {
    auto ptrs = definitions();
    return verify_service_definitions(std::span<const ServiceDefinition* const>(ptrs));
}

const ServiceDefinition* ServiceDefinitionSet::find_service(std::string_view service_name) const noexcept {
    for (const auto& d : defs_)
        if (d->name == service_name) return d.get();
    return nullptr;
}

NamedTypeRef ServiceDefinitionSet::find(std::string_view type_name, std::string_view context_service) const {
    auto dot = type_name.rfind('.');
    if (dot != std::string_view::npos) {
        const auto* s = find_service(type_name.substr(0, dot));
        return s ? find_in(*s, type_name.substr(dot + 1)) : NamedTypeRef{};
    }
    const auto* s = find_service(context_service);
    if (!s) return {};
    if (auto r = find_in(*s, type_name)) return r;
    for (const auto& u : s->usings)
        if (u.unqualified_name == type_name && u.qualified_name.find('.') != std::string::npos)
            return find(u.qualified_name, {});
    return {};
}

std::vector<const ServiceDefinition*> ServiceDefinitionSet::definitions() const {
    std::vector<const ServiceDefinition*> v;
    v.reserve(defs_.size());
    for (const auto& d : defs_) v.push_back(d.get());
    return v;
}

}  // namespace rr::robdef
