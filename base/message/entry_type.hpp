// MessageEntryType codes (wire.md §4; CORE RobotRaconteurConstants.h enum MessageEntryType).
// Odd = request or packet, even = response; response = request + 1.
#pragma once

#include <cstdint>

namespace rr {

enum class MessageEntryType : std::uint16_t {
    Null = 0,
    StreamOp = 1,
    StreamOpRet = 2,
    StreamCheckCapability = 3,
    StreamCheckCapabilityRet = 4,
    GetServiceDesc = 101,
    GetServiceDescRet = 102,
    ObjectTypeName = 103,
    ObjectTypeNameRet = 104,
    ServiceClosed = 105,
    ServiceClosedRet = 106,
    ConnectClient = 107,
    ConnectClientRet = 108,
    DisconnectClient = 109,
    DisconnectClientRet = 110,
    ConnectionTest = 111,
    ConnectionTestRet = 112,
    GetNodeInfo = 113,
    GetNodeInfoRet = 114,
    ReconnectClient = 115,
    ReconnectClientRet = 116,
    NodeCheckCapability = 117,
    NodeCheckCapabilityRet = 118,
    GetServiceAttributes = 119,
    GetServiceAttributesRet = 120,
    ConnectClientCombined = 121,
    ConnectClientCombinedRet = 122,
    EndpointCheckCapability = 501,
    EndpointCheckCapabilityRet = 502,
    ServiceCheckCapabilityReq = 1101,
    ServiceCheckCapabilityRet = 1102,
    ClientKeepAliveReq = 1105,
    ClientKeepAliveRet = 1106,
    ClientSessionOpReq = 1107,
    ClientSessionOpRet = 1108,
    ServicePathReleasedReq = 1109,
    ServicePathReleasedRet = 1110,
    PropertyGetReq = 1111,
    PropertyGetRes = 1112,
    PropertySetReq = 1113,
    PropertySetRes = 1114,
    FunctionCallReq = 1121,
    FunctionCallRes = 1122,
    GeneratorNextReq = 1123,
    GeneratorNextRes = 1124,
    EventReq = 1131,
    EventRes = 1132,
    PipePacket = 1141,
    PipePacketRet = 1142,
    PipeConnectReq = 1143,
    PipeConnectRet = 1144,
    PipeDisconnectReq = 1145,
    PipeDisconnectRet = 1146,
    PipeClosed = 1147,
    PipeClosedRet = 1148,
    CallbackCallReq = 1151,
    CallbackCallRet = 1152,
    WirePacket = 1161,
    WirePacketRet = 1162,
    WireConnectReq = 1163,
    WireConnectRet = 1164,
    WireDisconnectReq = 1165,
    WireDisconnectRet = 1166,
    WireClosed = 1167,
    WireClosedRet = 1168,
    MemoryRead = 1171,
    MemoryReadRet = 1172,
    MemoryWrite = 1173,
    MemoryWriteRet = 1174,
    MemoryGetParam = 1175,
    MemoryGetParamRet = 1176,
    WirePeekInValueReq = 1181,
    WirePeekInValueRet = 1182,
    WirePeekOutValueReq = 1183,
    WirePeekOutValueRet = 1184,
    WirePokeOutValueReq = 1185,
    WirePokeOutValueRet = 1186,
    WireTransportOpReq = 11161,
    WireTransportOpRet = 11162,
    WireTransportEvent = 11163,
    WireTransportEventRet = 11164,
};

constexpr bool is_request(MessageEntryType t) noexcept {
    return (static_cast<std::uint16_t>(t) & 1u) == 1u;
}

/// Entry types 101–500 are special requests: handled by the node, alone in their message (wire.md §4).
constexpr bool is_special_request(MessageEntryType t) noexcept {
    auto c = static_cast<std::uint16_t>(t);
    return c > 100 && c <= 500;
}

/// Entry types < 100 never leave the transport (stream ops, capability checks).
constexpr bool is_transport_internal(MessageEntryType t) noexcept {
    return static_cast<std::uint16_t>(t) < 100;
}

}  // namespace rr
