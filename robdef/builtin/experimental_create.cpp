#include "robdef/builtin/experimental_create.hpp"

namespace rr::robdef {

std::string_view experimental_create_robdef() noexcept {
    // Same members as the paper's definition (seed-examples/experimental.create.robdef); modern syntax.
    static constexpr std::string_view kText =
        "# Sample interface to an iRobot Create (the seed paper's example, modernized: stdver 0.10,\n"
        "# constant names without dots).\n"
        "service experimental.create\n"
        "\n"
        "stdver 0.10\n"
        "\n"
        "# One sensor reading; the layout of Data is documented by the device.\n"
        "struct SensorPacket\n"
        "    field uint8 ID\n"
        "    field uint8[] Data\n"
        "end\n"
        "\n"
        "object Create\n"
        "    # Drive radius values: straight ahead, spin in place.\n"
        "    constant int16 DRIVE_STRAIGHT 32767\n"
        "    constant int16 SPIN_CLOCKWISE -1\n"
        "    constant int16 SPIN_COUNTERCLOCKWISE 1\n"
        "\n"
        "    # velocity in mm/s, radius in mm (or one of the constants above)\n"
        "    function void Drive(int16 velocity, int16 radius)\n"
        "\n"
        "    function void StartStreaming()\n"
        "    function void StopStreaming()\n"
        "\n"
        "    property int32 DistanceTraveled [readonly]\n"
        "    property int32 AngleTraveled [readonly]\n"
        "    property uint8 Bumpers [readonly]\n"
        "\n"
        "    event Bump()\n"
        "\n"
        "    wire SensorPacket packets [readonly]\n"
        "\n"
        "    callback uint8[] play_callback(int32 DistanceTraveled, int32 AngleTraveled)\n"
        "end\n";
    return kText;
}

}  // namespace rr::robdef
