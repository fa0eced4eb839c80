#include "server/record/formats/formats.hpp"

namespace rr::server::record {

const RecordingFormats& builtin_recording_formats() {
    static const RecordingFormats formats{json_format(), robotraconteur_format(), foxglove_image_format()};
    return formats;
}

}  // namespace rr::server::record
