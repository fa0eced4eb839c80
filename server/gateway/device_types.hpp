// The robdef types of one device as the JSON API needs them: the device's service definition texts
// parsed into one ServiceDefinitionSet, object types looked up by qualified name, and member summaries
// for GET /api/devices/{name} (docs/json-api.md).
//
// Immutable once built, apart from the JSON text plans compiled on first use (behind a mutex); shared
// between threads through shared_ptr<const DeviceTypes>.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/codec/limits.hpp"
#include "base/error/rr_error.hpp"
#include "core/json/element_json_plan.hpp"
#include "robdef/service_definition_set.hpp"

namespace rr::server::gateway {

class DeviceTypes {
public:
    /// Parses every text (the root object's definition first, as ConnectClientCombined gives them).
    /// Errors: ServiceDefinitionError naming the file and line.
    static Result<std::shared_ptr<const DeviceTypes>> parse(std::vector<std::string> texts);

    const std::vector<std::string>& texts() const noexcept { return texts_; }
    const robdef::ServiceDefinitionSet& set() const noexcept { return set_; }

    struct Object {
        const robdef::ServiceDefinition* service = nullptr;  ///< defines the object: context for unqualified names
        const robdef::ServiceEntryDefinition* entry = nullptr;
    };
    /// The object type `svc.Name` (qualified), or nothing.
    std::optional<Object> find_object(std::string_view qualified_name) const;

    /// The plan that writes elements of `type` straight to JSON text (core/json/element_json_plan.hpp),
    /// compiled on the first call and kept as long as these types. `type` is a member's type or
    /// parameter inside set(), its unqualified names those of `context_service`. nullptr when the plan
    /// does not cover the type (the general path renders it then). Thread-safe.
    const element_json_text::Plan* json_text_plan(const robdef::TypeDefinition& type, std::string_view context_service,
                                                  const Limits& limits) const;

private:
    DeviceTypes() = default;
    std::vector<std::string> texts_;
    robdef::ServiceDefinitionSet set_;
    struct PlanEntry {
        const robdef::TypeDefinition* type;
        std::size_t max_depth;
        std::shared_ptr<const element_json_text::Plan> plan;  // null: not covered
    };
    mutable std::mutex plans_mutex_;
    mutable std::vector<PlanEntry> plans_;
};

/// `[{"name", "kind", "type", "modifiers", "parameters": [{"name", "type"}]}, …]` for the members of an
/// object, in definition order. `type` is the robdef type text (a function's return type; null for
/// events); `kind` the robdef keyword (property, function, event, objref, pipe, callback, wire, memory).
nlohmann::json member_summary(const robdef::ServiceEntryDefinition& object);

}  // namespace rr::server::gateway
