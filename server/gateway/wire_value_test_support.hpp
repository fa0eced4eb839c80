// Wire values for the gateway's tests: a WirePacket entry holding one double (element "packet"),
// shared as the device's mirror shares it, and the double read back. Test code only.
#pragma once

#include <catch2/catch.hpp>

#include <memory>
#include <utility>

#include "core/session/elements.hpp"
#include "server/gateway/shared_entry.hpp"

namespace rr::server::gateway::testing {

/// A shared WirePacket entry whose element "packet" is the scalar double `v`.
inline SharedEntryPtr wire_packet_value(double v) {
    MessageEntry e;
    e.entry_type = MessageEntryType::WirePacket;
    e.elements.push_back(make_scalar_element<double>("packet", v));
    return std::make_shared<const SharedEntry>(std::move(e));
}

/// The double in `e`'s element "packet" (a Catch2 REQUIRE fails when it is missing or not a double).
inline double packet_value_of(const SharedEntryPtr& e) {
    double v = -1;
    REQUIRE(read_scalar(*e->entry().find("packet"), v));
    return v;
}

}  // namespace rr::server::gateway::testing
