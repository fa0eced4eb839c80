// Members below a device's root object, for recording (docs/recording.md "Objects below the root"):
// a recorded member is named by the object's path relative to the root, as the JSON API's `object=`
// parameter names it (`Webcams[0]`, `arm.tool`), then `.` and the member: `Webcams[0].FrameStream`
// (split_member_path, base/names/object_path.hpp). The object's type comes from the declared types of
// the objrefs on the way (the device's robdef, core/names/object_path_walk.hpp), so a recording starts
// without asking the device (RR's ObjectTypeName is asynchronous).
#pragma once

#include <string>
#include <string_view>

#include "base/error/rr_error.hpp"
#include "base/names/object_path.hpp"
#include "server/gateway/device_types.hpp"

namespace rr::server::record {

using ::rr::MemberPath;
using ::rr::split_member_path;

/// The topic of a recorded member's channels: `<device>/<member>` for the root (object_path ""),
/// `<device>/<object_path>/<member>` below it, e.g. `webcam/Webcams[0]/FrameStream`. object_path is
/// normalized (object_below), so an index holds no '/' (it is `%2f`) and the topic splits at '/'.
std::string channel_topic(std::string_view device, std::string_view object_path, std::string_view member);

/// An object below the root, found through objrefs.
struct ObjectBelow {
    std::string path;         ///< the relative path normalized (indexes encoded as in RR service paths)
    std::string object_type;  ///< qualified, as declared by the last objref
    gateway::DeviceTypes::Object object;
};

/// The object at `relative` below an object of type `root_type`: parse_object_path, then
/// walk_object_path over the device's definitions; their errors (InvalidArgument): a malformed path,
/// no objref of that name, a `varobject` objref (its type is only known from the device), an index
/// missing on an indexed objref (`{int32}`, `{string}`, `[]`) or given to a plain one, a type not
/// among the device's definitions.
Result<ObjectBelow> object_below(const gateway::DeviceTypes& types, std::string_view root_type, std::string_view relative);

}  // namespace rr::server::record
