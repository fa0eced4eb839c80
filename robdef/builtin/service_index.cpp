#include "robdef/builtin/service_index.hpp"

namespace rr::robdef {

std::string_view service_index_robdef() noexcept {
    // Members and types per robdef.md §13. No stdver: the official definition declares none, and the
    // canonical text clients compare against has none either.
    static constexpr std::string_view kText =
        "service RobotRaconteurServiceIndex\n"
        "\n"
        "# One node seen by this node (routed or detected).\n"
        "struct NodeInfo\n"
        "    field string NodeName\n"
        "    field uint8[16] NodeID\n"
        "    field string{int32} ServiceIndexConnectionURL\n"
        "end\n"
        "\n"
        "# One service registered on this node.\n"
        "struct ServiceInfo\n"
        "    field string Name\n"
        "    field string RootObjectType\n"
        "    field string{int32} RootObjectImplements\n"
        "    field string{int32} ConnectionURL\n"
        "    field varvalue{string} Attributes\n"
        "end\n"
        "\n"
        "object ServiceIndex\n"
        "    function ServiceInfo{int32} GetLocalNodeServices()\n"
        "    function NodeInfo{int32} GetRoutedNodes()\n"
        "    function NodeInfo{int32} GetDetectedNodes()\n"
        "    event LocalNodeServicesChanged()\n"
        "end\n";
    return kText;
}

}  // namespace rr::robdef
