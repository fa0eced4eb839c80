#include "server/gateway/device_types.hpp"

#include "core/names/object_path_walk.hpp"

namespace rr::server::gateway {

Result<std::shared_ptr<const DeviceTypes>> DeviceTypes::parse(std::vector<std::string> texts) {
    std::shared_ptr<DeviceTypes> t(new DeviceTypes());
    for (std::size_t i = 0; i < texts.size(); ++i) {
        auto r = t->set_.add_text(texts[i], "device definition " + std::to_string(i + 1));
        if (!r) return r.take_error();
    }
    t->texts_ = std::move(texts);
    return std::shared_ptr<const DeviceTypes>(std::move(t));
}

std::optional<DeviceTypes::Object> DeviceTypes::find_object(std::string_view qualified_name) const {
    auto at = find_object_type(set_, qualified_name);
    if (!at) return std::nullopt;
    return Object{at->service, at->object};
}

const element_json_text::Plan* DeviceTypes::json_text_plan(const robdef::TypeDefinition& type,
                                                           std::string_view context_service,
                                                           const Limits& limits) const {
    std::lock_guard lock(plans_mutex_);
    for (const auto& e : plans_)
        if (e.type == &type && e.max_depth == limits.max_nesting_depth) return e.plan.get();
    auto plan = element_json_text::Plan::compile(type, set_, context_service, limits);
    plans_.push_back(PlanEntry{&type, limits.max_nesting_depth, plan});
    return plan.get();
}

nlohmann::json member_summary(const robdef::ServiceEntryDefinition& object) {
    auto members = nlohmann::json::array();
    for (const auto& m : object.members) {
        nlohmann::json j;
        j["name"] = m.name;
        j["kind"] = std::string(robdef::member_kind_keyword(m.kind));
        if (m.kind == robdef::MemberKind::event)
            j["type"] = nullptr;
        else
            j["type"] = m.type.to_string();
        j["modifiers"] = m.modifiers;
        auto params = nlohmann::json::array();
        for (const auto& p : m.parameters) params.push_back({{"name", p.name}, {"type", p.to_string()}});
        j["parameters"] = std::move(params);
        members.push_back(std::move(j));
    }
    return members;
}

}  // namespace rr::server::gateway
