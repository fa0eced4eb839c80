// Walking an object path (base/names/object_path.hpp) through the objrefs' declared types over a
// definition set: the type of the object at `arms[left].tool` below a `example.arm.Cell` is the type its
// last objref declares, found without asking the device. Above robdef (it reads robdef's type model), so
// in core/, compiled into rr_core; the parser is in base/.
//
// Errors (InvalidArgument), `P` the path's text as given to parse_object_path, `T` the type walked so far:
//   unknown object type R                                    (the root type)
//   object "P": T has no member "x"
//   object "P": T member "x" is a property, not an objref    (any other kind)
//   object "P": T objref "x" is a varobject (its type is known only to the device)
//   object "P": T objref "x" needs an index (Tool{int32})
//   object "P": T objref "x" takes no index
//   object "P": T objref "x": unknown object type U
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "base/error/rr_error.hpp"
#include "base/names/object_path.hpp"
#include "robdef/service_definition_set.hpp"

namespace rr {

/// An object type of a definition set.
struct ObjectTypeAt {
    std::string object_type;                               ///< qualified: `svc.Name`
    const robdef::ServiceDefinition* service = nullptr;    ///< defines it (context for unqualified names)
    const robdef::ServiceEntryDefinition* object = nullptr;
};

/// The object type `qualified` (`svc.Name`) of `set`, or nothing.
std::optional<ObjectTypeAt> find_object_type(const robdef::ServiceDefinitionSet& set, std::string_view qualified);

/// The object at `path` below an object of type `root_type`: each segment an objref of the object
/// reached so far, indexed exactly when it is declared with a container or an array (`{int32}`,
/// `{string}`, `[]`). `given` is the path's text for the messages (the user's, not the normalized one).
Result<ObjectTypeAt> walk_object_path(const robdef::ServiceDefinitionSet& set, std::string_view root_type, const ObjectPath& path,
                                      std::string_view given);

}  // namespace rr
