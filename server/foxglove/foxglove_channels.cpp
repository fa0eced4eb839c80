#include "server/foxglove/foxglove_channels.hpp"

#include "server/record/formats/json_format.hpp"
#include "server/record/json_schema.hpp"
#include "server/record/object_path.hpp"

namespace rr::server::foxglove {

using gateway::MemberTarget;

namespace {

LiveKind kind_of(record::RecordedKind k) {
    switch (k) {
        case record::RecordedKind::wire: return LiveKind::wire;
        case record::RecordedKind::pipe: return LiveKind::pipe;
        case record::RecordedKind::event: return LiveKind::event;
        case record::RecordedKind::property: return LiveKind::property;
    }
    return LiveKind::wire;
}

bool is_channel(robdef::MemberKind k) {
    return k == robdef::MemberKind::wire || k == robdef::MemberKind::pipe || k == robdef::MemberKind::event;
}

}  // namespace

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

    // The root and the configured objects below it.
    struct Object {
        std::string path, type;
        gateway::DeviceTypes::Object object;
    };
    std::vector<Object> all{{"", root_type, *root}};
    for (const auto& relative : objects) {
        auto below = record::object_below(*types, root_type, relative);
        if (!below) return fail(MessageErrorType::InvalidArgument, "foxglove: objects: \"" + relative + "\": " + below.error().message);
        all.push_back({below->path, below->object_type, below->object});
    }

    std::vector<LiveMember> out;
    // Channels: the recorder's members and channels.
    std::vector<std::string> names;
    for (const auto& o : all)
        for (const auto& m : o.object.entry->members)
            if (is_channel(m.kind)) names.push_back(o.path.empty() ? m.name : o.path + "." + m.name);
    if (!names.empty()) {
        auto recorded = record::recorded_members(device, api, names, {});
        if (!recorded) return recorded.take_error();
        for (auto& r : *recorded) {
            auto rm = std::make_shared<const record::RecordedMember>(std::move(r));
            const auto channel = record::json_channel(*rm);
            LiveMember live;
            live.kind = kind_of(rm->kind);
            live.target = rm->target;
            live.object = record::metadata_value(rm->metadata, record::channel_key::path);
            live.topic = channel.topic;
            live.schema_name = channel.schema_name;
            live.schema = channel.schema;
            live.writable = rm->target->member->direction() != robdef::MemberDirection::readonly;
            live.recorded = rm;
            if (auto kind = record::foxglove_image_kind_of(*rm)) {
                const auto image = record::foxglove_image_channel(*rm, *kind);
                LiveMember pictures = live;
                pictures.topic = image.topic;
                pictures.schema_name = image.schema_name;
                pictures.schema = image.schema;
                pictures.writable = false;
                pictures.image = kind;
                out.push_back(std::move(live));
                out.push_back(std::move(pictures));
                continue;
            }
            out.push_back(std::move(live));
        }
    }

    // Parameters (readable properties) and services (functions).
    for (const auto& o : all) {
        for (const auto& m : o.object.entry->members) {
            const bool property = m.kind == robdef::MemberKind::property && m.direction() != robdef::MemberDirection::writeonly;
            if (!property && m.kind != robdef::MemberKind::function) continue;
            auto t = std::make_shared<MemberTarget>();
            t->device = device;
            t->types = types;
            t->path = o.path.empty() ? name : name + "." + o.path;
            t->object_type = o.type;
            t->service = o.object.service;
            t->object = o.object.entry;
            t->member = &m;
            LiveMember live;
            live.kind = property ? LiveKind::property : LiveKind::function;
            live.object = o.path;
            live.topic = record::channel_topic(name, o.path, m.name);
            live.schema_name = o.type + "." + m.name;
            live.writable = m.direction() != robdef::MemberDirection::readonly;
            if (!property) {
                const auto& lookup = types->set();
                const std::string_view context = o.object.service->name;
                // The request: the arguments by name, as the JSON API's call takes them, in the
                // definition's order (a client's form lists them so).
                nlohmann::ordered_json props = nlohmann::ordered_json::object();
                for (const auto& p : m.parameters) {
                    auto s = record::value_schema(p, lookup, context);
                    if (!s.is_null()) props[p.name] = nlohmann::ordered_json::parse(s.dump());
                }
                nlohmann::ordered_json request = nlohmann::ordered_json::object();
                request["title"] = live.schema_name + " request";
                request["type"] = "object";
                request["properties"] = std::move(props);
                live.schema = request.dump();
                nlohmann::json response{{"title", live.schema_name + " response"}, {"type", "object"}};
                auto r = record::value_schema(m.type, lookup, context);
                response["properties"] = r.is_null() ? nlohmann::json::object() : nlohmann::json{{"return", r}};
                live.response_schema = response.dump();
            }
            live.target = std::move(t);
            out.push_back(std::move(live));
        }
    }
    return out;
}

std::optional<std::string> channel_message(const gateway::JsonApi& api, const LiveMember& member, const gateway::SharedEntry& entry,
                                           std::uint64_t receive_ns) {
    if (!member.recorded) return std::nullopt;
    if (member.image) return record::foxglove_image_message(api, *member.recorded, *member.image, entry.entry(), receive_ns);
    return record::json_message(api, *member.recorded, entry);
}

}  // namespace rr::server::foxglove
