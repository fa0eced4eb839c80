// The built-in recording formats (recording_format.hpp), one file each; builtin_recording_formats()
// (formats.cpp) lists them in the order their channels are added to a file.
#pragma once

#include <memory>

#include "server/record/recording_format.hpp"

namespace rr::server::record {

/// `json`: the JSON API's mapping of each value, a JSON Schema per channel (json_format.cpp).
std::shared_ptr<const RecordingFormat> json_format();
/// `robotraconteur`: each entry's bytes in RR message format 4, the format replay plays
/// (robotraconteur_format.cpp).
std::shared_ptr<const RecordingFormat> robotraconteur_format();
/// `foxglove_image`: standard images also as Foxglove's RawImage / CompressedImage, with `json` and
/// RecordingSpec::foxglove_images (foxglove_image_format.cpp).
std::shared_ptr<const RecordingFormat> foxglove_image_format();

}  // namespace rr::server::record
