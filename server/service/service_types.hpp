// The service definitions a typed service serves: robdef texts, parsed and verified once, plus the
// type lookup used to check and pack every value it sends and receives (robdef.md §10; wire.md §3.2,
// §6.4 for how the texts travel in ConnectClientCombined / GetServiceDesc).
//
// Immutable after create(): share it (std::shared_ptr<const ServiceTypes>) between the ServiceObjects
// and the ObjectService built on it; every member function is safe to call from any thread.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"
#include "robdef/service_definition_set.hpp"

namespace rr::server {

class ServiceTypes {
public:
    /// Parses every text (each one `service …` definition) and verifies them as one set together
    /// with the built-in RobotRaconteurServiceIndex. Warnings are ignored.
    /// Errors: ServiceDefinitionError with every diagnostic (`file:line: error: …`, one per line);
    /// InvalidArgument when `texts` is empty.
    static Result<std::shared_ptr<const ServiceTypes>> create(std::vector<std::string> texts);

    /// The verified set: a robdef::TypeLookup for pack_value / unpack_value.
    const robdef::ServiceDefinitionSet& set() const noexcept { return set_; }

    /// Object type by qualified name (`svc.Obj`), or nullptr.
    const robdef::ServiceEntryDefinition* find_object(std::string_view qualified_name) const noexcept;

    /// The text of one definition, exactly as given to create(); nullopt when unknown.
    std::optional<std::string> text(std::string_view service_name) const;

    /// Texts for a client of an object of service `service_name`: that definition first, then every
    /// definition it imports, transitively, each once (what ConnectClientCombined returns as
    /// `servicedefs`). Imports not in the set (the built-in) are skipped.
    std::vector<std::string> texts_for(std::string_view service_name) const;

    /// True when `type` (qualified object type) is `base` or implements it, directly or through
    /// other implemented objects.
    bool object_is_a(std::string_view type, std::string_view base) const;

    /// Qualified names of the objects `type` implements directly (`implements` lines, resolved
    /// against the object's own service).
    std::vector<std::string> implements_of(std::string_view type) const;

    /// A user exception declared in the robdef (wire.md §5.1: RemoteError, code 100, errorname
    /// `svc.ExceptionName`). `exception` is qualified, or unqualified within `context_service`.
    /// An undeclared name gives an InternalError naming it (a programming error in the service), so a
    /// client never receives an exception name the robdef does not declare.
    RRError user_error(std::string_view exception, std::string message, std::string_view context_service = {}) const;

private:
    ServiceTypes() = default;
    struct Text {
        std::string service_name;
        std::string text;
    };
    robdef::ServiceDefinitionSet set_;
    std::vector<Text> texts_;
};

}  // namespace rr::server
