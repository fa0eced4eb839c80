#include "core/names/object_path_walk.hpp"

namespace rr {

std::optional<ObjectTypeAt> find_object_type(const robdef::ServiceDefinitionSet& set, std::string_view qualified) {
    const auto dot = qualified.rfind('.');
    if (dot == std::string_view::npos) return std::nullopt;
    const auto* service = set.find_service(qualified.substr(0, dot));
    if (!service) return std::nullopt;
    const auto* entry = service->find_entry(qualified.substr(dot + 1));
    if (!entry || entry->kind != robdef::EntryKind::object) return std::nullopt;
    return ObjectTypeAt{std::string(qualified), service, entry};
}

Result<ObjectTypeAt> walk_object_path(const robdef::ServiceDefinitionSet& set, std::string_view root_type, const ObjectPath& path,
                                      std::string_view given) {
    auto at = find_object_type(set, root_type);
    if (!at) return fail(MessageErrorType::InvalidArgument, "unknown object type " + std::string(root_type));
    for (const auto& segment : path.segments) {
        const std::string where = "object \"" + std::string(given) + "\": " + at->object_type;
        auto bad = [&](const std::string& what) { return fail(MessageErrorType::InvalidArgument, where + what); };
        const auto* m = at->object->find_member(segment.name);
        if (!m) return bad(" has no member \"" + segment.name + "\"");
        const std::string objref = " objref \"" + segment.name + "\"";
        if (m->kind != robdef::MemberKind::objref)
            return bad(" member \"" + segment.name + "\" is " + robdef::with_article(robdef::member_kind_keyword(m->kind)) + ", not an objref");
        if (m->type.base == DataTypes::varobject_t) return bad(objref + " is a varobject (its type is known only to the device)");
        const bool wants_index = m->type.container != robdef::ContainerKind::none || m->type.array != robdef::ArrayKind::none;
        if (wants_index && !segment.has_index) return bad(objref + " needs an index (" + m->type.to_string() + ")");
        if (!wants_index && segment.has_index) return bad(objref + " takes no index");
        // Unresolved (not among the definitions): no qualified name, the type as written.
        const std::string& type = m->type.qualified_name.empty() ? m->type.type_name : m->type.qualified_name;
        auto next = find_object_type(set, type);
        if (!next) return bad(objref + ": unknown object type " + type);
        at = std::move(next);
    }
    return std::move(*at);
}

}  // namespace rr
