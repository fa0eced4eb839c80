// `experimental.createwebcam`: the seed paper's webcam service definition (Robot Raconteur 0.8),
// modernized by us for the demo device (server/demo): stdver 0.10 instead of `option version`, `end`
// instead of `end struct` / `end object`; the members and their types are the paper's. `[readonly]`
// on Name and FrameStream (the service only sends frames), which changes no member.
#pragma once

#include <string_view>

namespace rr::robdef {

/// Definition text (LF line ends, verifies without diagnostics together with the built-in set).
std::string_view experimental_createwebcam_robdef() noexcept;

inline constexpr std::string_view kExperimentalCreateWebcamServiceName = "experimental.createwebcam";
inline constexpr std::string_view kExperimentalWebcamHostObjectType = "experimental.createwebcam.WebcamHost";
inline constexpr std::string_view kExperimentalWebcamObjectType = "experimental.createwebcam.Webcam";
inline constexpr std::string_view kExperimentalWebcamImage = "experimental.createwebcam.WebcamImage";
inline constexpr std::string_view kExperimentalWebcamImageSize = "experimental.createwebcam.WebcamImage_size";

}  // namespace rr::robdef
