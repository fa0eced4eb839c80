#include "robdef/builtin/experimental_createwebcam.hpp"

namespace rr::robdef {

std::string_view experimental_createwebcam_robdef() noexcept {
    // Same members as the paper's definition (seed-examples/experimental.createwebcam.robdef).
    static constexpr std::string_view kText =
        "# Sample interface to webcams (the seed paper's example, modernized: stdver 0.10).\n"
        "service experimental.createwebcam\n"
        "\n"
        "stdver 0.10\n"
        "\n"
        "# One image: data holds height rows of step bytes each.\n"
        "struct WebcamImage\n"
        "    field int32 width\n"
        "    field int32 height\n"
        "    field int32 step\n"
        "    field uint8[] data\n"
        "end\n"
        "\n"
        "# The shape of the image CaptureFrameToBuffer stored in the memories.\n"
        "struct WebcamImage_size\n"
        "    field int32 width\n"
        "    field int32 height\n"
        "    field int32 step\n"
        "end\n"
        "\n"
        "object Webcam\n"
        "    property string Name [readonly]\n"
        "    function WebcamImage CaptureFrame()\n"
        "\n"
        "    function void StartStreaming()\n"
        "    function void StopStreaming()\n"
        "    pipe WebcamImage FrameStream [readonly]\n"
        "\n"
        "    function WebcamImage_size CaptureFrameToBuffer()\n"
        "    memory uint8[] buffer\n"
        "    memory uint8[*] multidimbuffer\n"
        "end\n"
        "\n"
        "object WebcamHost\n"
        "    property string{int32} WebcamNames [readonly]\n"
        "    objref Webcam{int32} Webcams\n"
        "end\n";
    return kText;
}

}  // namespace rr::robdef
