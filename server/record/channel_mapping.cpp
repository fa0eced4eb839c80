#include "server/record/channel_mapping.hpp"

#include "robdef/service_definition.hpp"
#include "server/gateway/device_mirror.hpp"
#include "server/record/object_path.hpp"

namespace rr::server::record {
namespace {

// The object's path below the root from a target's service path in gateway naming (`<device>` or
// `<device>.<relative path>`): "" for the root.
std::string object_path_of(const std::string& service_path, const std::string& device) {
    return service_path.size() > device.size() ? service_path.substr(device.size() + 1) : std::string();
}

}  // namespace

Result<std::vector<RecordedMember>> recorded_members(const std::shared_ptr<gateway::DeviceMirror>& device, const gateway::JsonApi& api,
                                                     const std::vector<std::string>& names, std::chrono::milliseconds property_period) {
    const std::string device_name = device->config().name;
    gateway::ApiError type_error;
    auto types = api.types_for(*device, &type_error);
    if (!types) return fail(MessageErrorType::InvalidState, "record: device \"" + device_name + "\": " + type_error.message);
    const std::string object_type = device->object_type();
    auto object = types->find_object(object_type);
    if (!object) return fail(MessageErrorType::InvalidState, "record: device \"" + device_name + "\": unknown root type " + object_type);

    std::vector<RecordedMember> members;
    // `m` of the object at `below` (nullptr: the root).
    auto add = [&](const robdef::MemberDefinition& m, const ObjectBelow* below = nullptr) -> Result<void> {
        RecordedMember r;
        switch (m.kind) {
            case robdef::MemberKind::wire: r.kind = RecordedKind::wire; break;
            case robdef::MemberKind::pipe: r.kind = RecordedKind::pipe; break;
            case robdef::MemberKind::event: r.kind = RecordedKind::event; break;
            case robdef::MemberKind::property:
                if (m.direction() == robdef::MemberDirection::writeonly)
                    return fail(MessageErrorType::InvalidArgument, "record: members: property \"" + m.name + "\" is write-only");
                r.kind = RecordedKind::property;
                break;
            default:
                return fail(MessageErrorType::InvalidArgument,
                            "record: members: \"" + m.name + "\" is " + robdef::with_article(robdef::member_kind_keyword(m.kind)) +
                                " (wires, pipes, events and properties can be recorded)");
        }
        auto t = std::make_shared<gateway::MemberTarget>();
        t->device = device;
        t->types = types;
        t->path = below ? device_name + "." + below->path : device_name;
        t->object_type = below ? below->object_type : object_type;
        t->service = below ? below->object.service : object->service;
        t->object = below ? below->object.entry : object->entry;
        t->member = &m;
        // What every channel of the member carries (channel_metadata.hpp).
        const std::string path = object_path_of(t->path, device_name);
        r.topic = channel_topic(device_name, path, m.name);
        r.metadata = {{channel_key::device, device_name},
                      {channel_key::member, m.name},
                      {channel_key::kind, std::string(member_kind_name(r.kind))},
                      {channel_key::object_type, t->object_type},
                      {channel_key::path, path},
                      {channel_key::root_type, object_type}};
        if (r.kind != RecordedKind::event) r.metadata[channel_key::type] = m.type.to_string();
        if (r.kind == RecordedKind::property)
            r.metadata[channel_key::period_ms] = std::to_string(property_period.count() > 0 ? property_period.count() : 1000);
        r.target = std::move(t);
        members.push_back(std::move(r));
        return {};
    };
    if (names.empty()) {
        for (const auto& m : object->entry->members) {
            const bool stream = m.kind == robdef::MemberKind::wire || m.kind == robdef::MemberKind::pipe ||
                                m.kind == robdef::MemberKind::event;
            const bool prop = m.kind == robdef::MemberKind::property && property_period.count() > 0 &&
                              m.direction() != robdef::MemberDirection::writeonly;
            if (stream || prop)
                if (auto r = add(m); !r) return r.take_error();
        }
    } else {
        for (const auto& name : names) {
            const auto split = split_member_path(name);
            if (split.object.empty()) {
                const auto* m = object->entry->find_member(name);
                if (!m) return fail(MessageErrorType::InvalidArgument, "record: members: " + object_type + " has no member \"" + name + "\"");
                if (auto r = add(*m); !r) return r.take_error();
                continue;
            }
            auto below = object_below(*types, object_type, split.object);
            if (!below) return fail(MessageErrorType::InvalidArgument, "record: members: \"" + name + "\": " + below.error().message);
            const auto* m = below->object.entry->find_member(split.member);
            if (!m)
                return fail(MessageErrorType::InvalidArgument, "record: members: \"" + name + "\": " + below->object_type +
                                                                   " has no member \"" + split.member + "\"");
            if (auto r = add(*m, &*below); !r) return r.take_error();
        }
    }
    if (members.empty()) return fail(MessageErrorType::InvalidArgument, "record: " + object_type + ": nothing to record");
    if (members.size() > 30000) return fail(MessageErrorType::InvalidArgument, "record: too many members");
    return members;
}

}  // namespace rr::server::record
