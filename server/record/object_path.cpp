#include "server/record/object_path.hpp"

#include "core/names/object_path_walk.hpp"

namespace rr::server::record {

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
    auto path = parse_object_path(relative);
    if (!path) return path.take_error();
    auto at = walk_object_path(types.set(), root_type, *path, relative);
    if (!at) return at.take_error();
    return ObjectBelow{path->text(), at->object_type, gateway::DeviceTypes::Object{at->service, at->object}};
}

}  // namespace rr::server::record
