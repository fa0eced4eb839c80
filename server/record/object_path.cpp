#include "server/record/object_path.hpp"

#include "server/gateway/json_api.hpp"

namespace rr::server::record {

MemberPath split_member_path(std::string_view name) {
    int depth = 0;
    for (std::size_t i = name.size(); i-- > 0;) {
        if (name[i] == ']') ++depth;
        else if (name[i] == '[' && depth > 0) --depth;
        else if (name[i] == '.' && depth == 0) return {std::string(name.substr(0, i)), std::string(name.substr(i + 1))};
    }
    return {"", std::string(name)};
}

std::string channel_topic(std::string_view device, std::string_view object_path, std::string_view member) {
    std::string topic(device);
    topic += '/';
    if (!object_path.empty()) {
        topic += object_path;
        topic += '/';
    }
    topic += member;
    return topic;
}

Result<ObjectBelow> object_below(const gateway::DeviceTypes& types, std::string_view root_type, std::string_view relative) {
    auto normalized = gateway::normalize_object_path(relative);
    if (!normalized) return normalized.take_error();
    ObjectBelow out;
    out.path = *normalized;
    out.object_type = std::string(root_type);
    auto object = types.find_object(root_type);
    if (!object) return fail(MessageErrorType::InvalidArgument, "unknown object type " + std::string(root_type));
    const std::string& path = out.path;
    std::size_t pos = 0;
    while (pos < path.size()) {
        // Normalized: segments are `name` or `name[encoded index]`, joined by '.', no '.' in an index.
        auto end = path.find('.', pos);
        if (end == std::string::npos) end = path.size();
        const std::string segment = path.substr(pos, end - pos);
        const auto bracket = segment.find('[');
        const std::string name = segment.substr(0, bracket);
        const bool indexed = bracket != std::string::npos;
        const std::string where = "object \"" + std::string(relative) + "\": " + out.object_type;
        const auto* m = object->entry->find_member(name);
        if (!m) return fail(MessageErrorType::InvalidArgument, where + " has no member \"" + name + "\"");
        if (m->kind != robdef::MemberKind::objref)
            return fail(MessageErrorType::InvalidArgument, where + " member \"" + name + "\" is " +
                                                               robdef::with_article(robdef::member_kind_keyword(m->kind)) +
                                                               ", not an objref");
        if (m->type.base == DataTypes::varobject_t)
            return fail(MessageErrorType::InvalidArgument,
                        where + " objref \"" + name + "\" is a varobject (its type is known only to the device): not recordable");
        const bool wants_index = m->type.container != robdef::ContainerKind::none || m->type.array != robdef::ArrayKind::none;
        if (wants_index && !indexed)
            return fail(MessageErrorType::InvalidArgument, where + " objref \"" + name + "\" needs an index (" + m->type.to_string() + ")");
        if (!wants_index && indexed)
            return fail(MessageErrorType::InvalidArgument, where + " objref \"" + name + "\" takes no index");
        out.object_type = m->type.qualified_name;
        object = types.find_object(out.object_type);
        if (!object)
            return fail(MessageErrorType::InvalidArgument, where + " objref \"" + name + "\": unknown object type " + out.object_type);
        pos = end + 1;
    }
    out.object = *object;
    return out;
}

}  // namespace rr::server::record
