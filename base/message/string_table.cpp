#include "base/message/string_table.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <unordered_map>

#include "base/codec/varint.hpp"

namespace rr {
namespace {

struct StandardString {
    std::uint32_t code;
    std::string_view text;
};

// The standard table (wire.md §2.6), ordered by code. "nodeid" (136, 140) and "ServiceIndex" (268, 588)
// appear twice, as in CORE; lookups by string return the first.
constexpr StandardString kStandardTable[] = {
    {0, ""}, {4, "array"}, {8, "attributes"}, {12, "AuthenticateUser"}, {16, "capabilities"},
    {20, "capabilities2"}, {24, "clientversion"}, {28, "confirmcodes"}, {32, "Continue"}, {36, "count"},
    {40, "CreateConnection"}, {44, "credentials"}, {48, "data"}, {52, "DimCount"}, {56, "Dimensions"},
    {60, "dims"}, {64, "errorname"}, {68, "errorparam"}, {72, "errorstring"}, {76, "errorsubname"},
    {80, "extraimports"}, {84, "false"}, {88, "GetRemoteNodeID"}, {92, "index"}, {96, "Length"},
    {100, "LogoutUser"}, {104, "MaxTransferSize"}, {108, "memorypos"}, {112, "messageversion"},
    {116, "MonitorContinueEnter"}, {120, "MonitorEnter"}, {124, "MonitorExit"}, {128, "mutualauth"},
    {132, "nanoseconds"}, {136, "nodeid"}, {140, "nodeid"}, {144, "nodename"}, {148, "nolock"},
    {152, "nolockread"}, {156, "null"}, {160, "objectimplements"}, {164, "objecttype"}, {168, "OK"},
    {172, "packet"}, {176, "packetnumber"}, {180, "packettime"}, {184, "parameter"}, {188, "password"},
    {192, "pause"}, {196, "perclient"}, {200, "readonly"}, {204, "ReleaseClientObjectLock"},
    {208, "ReleaseObjectLock"}, {212, "requestack"}, {216, "RequestClientObjectLock"}, {220, "RequestObjectLock"},
    {224, "resume"}, {228, "return"}, {232, "returnservicedefs"}, {236, "robotraconteur"}, {240, "RobotRaconteur"},
    {244, "RobotRaconteur.TimeSpec"}, {248, "seconds"}, {252, "seqno"}, {256, "service"}, {260, "servicedef"},
    {264, "servicedefs"}, {268, "ServiceIndex"}, {272, "servicename"}, {276, "servicepath"}, {280, "ServiceType"},
    {284, "stringtable"}, {288, "timeout"}, {292, "timespec"}, {296, "timestamp"}, {300, "true"},
    {304, "unreliable"}, {308, "urgent"}, {512, "username"}, {516, "value"}, {520, "writeonly"},
    {524, "Attributes"}, {528, "ConnectionURL"}, {532, "GetDetectedNodes"}, {536, "GetLocalNodeServices"},
    {540, "GetRoutedNodes"}, {544, "LocalNodeServicesChanged"}, {548, "Name"}, {552, "NodeID"}, {556, "NodeInfo"},
    {560, "NodeName"}, {564, "RobotRaconteurServiceIndex"}, {568, "RobotRaconteurServiceIndex.NodeInfo"},
    {572, "RobotRaconteurServiceIndex.ServiceIndex"}, {576, "RobotRaconteurServiceIndex.ServiceInfo"},
    {580, "RootObjectImplements"}, {584, "RootObjectType"}, {588, "ServiceIndex"},
    {592, "ServiceIndexConnectionURL"}, {596, "ServiceInfo"}, {600, "node"}, {604, "level"}, {608, "component"},
    {612, "componentname"}, {616, "componentobjectid"}, {620, "endpoint"}, {624, "member"}, {628, "message"},
    {632, "time"}, {636, "sourcefile"}, {640, "sourceline"}, {644, "threadid"}, {648, "fiberid"},
};

constexpr bool sorted_by_code() {
    for (std::size_t i = 1; i < std::size(kStandardTable); ++i)
        if (kStandardTable[i - 1].code >= kStandardTable[i].code) return false;
    return true;
}
static_assert(sorted_by_code(), "standard string table must be ordered by code");
static_assert(std::size(kStandardTable) == 113);

}  // namespace

std::optional<std::string_view> standard_string_for_code(std::uint32_t code) noexcept {
    auto it = std::lower_bound(std::begin(kStandardTable), std::end(kStandardTable), code,
                               [](const StandardString& e, std::uint32_t c) { return e.code < c; });
    if (it == std::end(kStandardTable) || it->code != code) return std::nullopt;
    return it->text;
}

std::optional<std::uint32_t> standard_code_for_string(std::string_view s) noexcept {
    for (const auto& e : kStandardTable)
        if (e.text.size() == s.size() && e.text == s) return e.code;
    return std::nullopt;
}

namespace {

// Sender-side replacement state for one message (CORE DoReplaceString).
class CodeAssigner {
public:
    CodeAssigner(const StringTableOptions& options, MessageHeader& header) : options_(options), header_(header) {}

    void replace(const std::string& s, std::optional<std::uint32_t>& code) {
        if (code || s.size() > kMaxStringTableStringBytes) return;
        if (options_.standard_table) {
            if (auto c = standard_code_for_string(s)) {
                code = *c;
                return;
            }
        }
        if (!options_.message_local) return;
        if (auto it = local_.find(s); it != local_.end()) {
            code = it->second;
            return;
        }
        std::size_t bytes = uint_x_size(next_) + uint_x_size(static_cast<std::uint32_t>(s.size())) + s.size();
        if (table_bytes_ + bytes > kMaxLocalStringTableBytes) return;  // table full: keep the string
        table_bytes_ += bytes;
        local_.emplace(s, next_);
        header_.string_table.emplace_back(next_, s);
        code = next_;
        next_ += 2;
    }

    void replace_in(MessageElement& e) {
        if (!e.number) replace(e.name, e.name_code);
        if (!e.type_name.empty()) replace(e.type_name, e.type_name_code);
        for (auto& child : e.elements) replace_in(child);
    }

private:
    const StringTableOptions& options_;
    MessageHeader& header_;
    std::unordered_map<std::string_view, std::uint32_t> local_;  // views into the message's own strings
    std::uint32_t next_ = 1;
    std::size_t table_bytes_ = 0;
};

void clear_codes(MessageElement& e) {
    e.name_code.reset();
    e.type_name_code.reset();
    for (auto& child : e.elements) clear_codes(child);
}

}  // namespace

void apply_string_table(Message& message, const StringTableOptions& options) {
    auto& h = message.header;
    if (!h.string_table.empty() || (h.v4_flags && (*h.v4_flags & message_flags::string_table))) return;
    CodeAssigner assign(options, h);
    for (auto& entry : message.entries) {
        assign.replace(entry.member_name, entry.member_name_code);
        assign.replace(entry.service_path, entry.service_path_code);
        for (auto& e : entry.elements) assign.replace_in(e);
    }
    if (!h.string_table.empty() && h.v4_flags) *h.v4_flags |= message_flags::string_table;
}

void clear_string_table_codes(Message& message) {
    auto& h = message.header;
    h.string_table.clear();
    if (h.v4_flags) *h.v4_flags &= static_cast<std::uint8_t>(~message_flags::string_table);
    for (auto& entry : message.entries) {
        entry.service_path_code.reset();
        entry.member_name_code.reset();
        for (auto& e : entry.elements) clear_codes(e);
    }
}

}  // namespace rr
