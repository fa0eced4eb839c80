#include "server/foxglove/foxglove_channels.hpp"

#include "server/gateway/json_push.hpp"
#include "server/record/json_schema.hpp"
#include "server/record/object_path.hpp"

namespace rr::server::foxglove {

using gateway::MemberTarget;

Result<std::vector<LiveMember>> device_members(const gateway::JsonApi& api, const std::shared_ptr<gateway::DeviceMirror>& device,
                                               const std::vector<std::string>& objects) {
    if (!device->upstream()) return fail(MessageErrorType::InvalidState, "device \"" + device->config().name + "\" is not connected");
    gateway::ApiError type_error;
    auto types = api.types_for(*device, &type_error);
    if (!types) return fail(MessageErrorType::InvalidState, "device \"" + device->config().name + "\": " + type_error.message);
    const std::string root_type = device->object_type();
    auto root = types->find_object(root_type);
    if (!root) return fail(MessageErrorType::InvalidState, "device \"" + device->config().name + "\": unknown root type " + root_type);
    const std::string& name = device->config().name;

    std::vector<LiveMember> out;
    auto add_object = [&](const gateway::DeviceTypes::Object& object, const std::string& object_type, const std::string& path) {
        for (const auto& m : object.entry->members) {
            LiveMember live;
            switch (m.kind) {
                case robdef::MemberKind::wire: live.kind = LiveKind::wire; break;
                case robdef::MemberKind::pipe: live.kind = LiveKind::pipe; break;
                case robdef::MemberKind::event: live.kind = LiveKind::event; break;
                case robdef::MemberKind::property:
                    if (m.direction() == robdef::MemberDirection::writeonly) continue;
                    live.kind = LiveKind::property;
                    break;
                case robdef::MemberKind::function: live.kind = LiveKind::function; break;
                default: continue;
            }
            auto t = std::make_shared<MemberTarget>();
            t->device = device;
            t->types = types;
            t->path = path.empty() ? name : name + "." + path;
            t->object_type = object_type;
            t->service = object.service;
            t->object = object.entry;
            t->member = &m;
            live.object = path;
            live.topic = record::channel_topic(name, path, m.name);
            live.schema_name = object_type + "." + m.name;
            live.writable = m.direction() != robdef::MemberDirection::readonly;
            const auto& lookup = types->set();
            const std::string_view context = object.service->name;
            switch (live.kind) {
                case LiveKind::wire: live.schema = record::wire_message_schema(m.type, lookup, context, live.schema_name).dump(); break;
                case LiveKind::event: live.schema = record::event_message_schema(m, lookup, context, live.schema_name).dump(); break;
                case LiveKind::pipe:
                case LiveKind::property: live.schema = record::value_message_schema(m.type, lookup, context, live.schema_name).dump(); break;
                case LiveKind::function: {
                    // The request: the arguments by name, as the JSON API's call takes them.
                    nlohmann::json props = nlohmann::json::object();
                    for (const auto& p : m.parameters) {
                        auto s = record::value_schema(p, lookup, context);
                        if (!s.is_null()) props[p.name] = std::move(s);
                    }
                    live.schema = nlohmann::json{{"title", live.schema_name + " request"}, {"type", "object"}, {"properties", props}}.dump();
                    nlohmann::json response{{"title", live.schema_name + " response"}, {"type", "object"}};
                    auto r = record::value_schema(m.type, lookup, context);
                    response["properties"] = r.is_null() ? nlohmann::json::object() : nlohmann::json{{"return", r}};
                    live.response_schema = response.dump();
                    break;
                }
            }
            live.target = std::move(t);
            std::optional<record::FoxgloveImageKind> image;
            if (live.kind == LiveKind::wire || live.kind == LiveKind::pipe) image = record::foxglove_image_kind(m.type, lookup, context);
            if (image) {
                LiveMember pictures = live;
                pictures.image = image;
                pictures.topic += "/foxglove";
                pictures.schema_name = std::string(record::foxglove_schema_name(*image));
                pictures.schema = record::foxglove_image_schema(*image).dump();
                pictures.writable = false;
                out.push_back(std::move(live));
                out.push_back(std::move(pictures));
                continue;
            }
            out.push_back(std::move(live));
        }
    };
    add_object(*root, root_type, "");
    for (const auto& relative : objects) {
        auto below = record::object_below(*types, root_type, relative);
        if (!below) return fail(MessageErrorType::InvalidArgument, "foxglove: objects: \"" + relative + "\": " + below.error().message);
        add_object(below->object, below->object_type, below->path);
    }
    return out;
}

std::string entry_message(const gateway::JsonApi& api, const MessageEntry& entry, const LiveMember& member) {
    return member.kind == LiveKind::wire ? gateway::wire_push_text(api, entry, *member.target)
                                         : gateway::event_push_text(api, entry, *member.target);
}

std::string packet_message(const gateway::JsonApi& api, const MessageElement& packet, const LiveMember& member) {
    nlohmann::json body = nlohmann::json::object();
    auto j = api.element_json(packet, member.target->member->type, *member.target);
    if (j)
        body["value"] = std::move(j.value);
    else
        body["error"] = gateway::error_object(*j.error);
    return gateway::json_text(body);
}

std::optional<std::string> image_message(const gateway::JsonApi& api, const MessageElement& element, const LiveMember& member,
                                         std::uint64_t receive_ns) {
    if (!member.image) return std::nullopt;
    BinaryArrays binary;
    auto j = api.element_json(element, member.target->member->type, *member.target, &binary);
    if (!j) return std::nullopt;
    return record::foxglove_image_message(*member.image, j.value, binary, receive_ns);
}

}  // namespace rr::server::foxglove
