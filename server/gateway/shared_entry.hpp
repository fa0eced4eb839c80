// One upstream wire value or event as the gateway's own subscribers (the JSON API sockets) see it:
// a single shared copy for all of them, plus one cached rendering made by the first subscriber that
// needs it, so a value fanned out to N WebSocket clients is converted to JSON once, not N times.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "core/message/message.hpp"

namespace rr::server::gateway {

class SharedEntry {
public:
    explicit SharedEntry(MessageEntry entry) : entry_(std::move(entry)) {}

    const MessageEntry& entry() const { return entry_; }

    /// The text `render(entry())` returns, computed once; callers on other threads wait for it. Every
    /// subscriber must pass an equivalent `render` (the same conversion for the same member).
    template <class Render>
    const std::string& rendered(Render&& render) const {
        std::call_once(once_, [&] { rendered_ = std::forward<Render>(render)(entry_); });
        return rendered_;
    }

private:
    MessageEntry entry_;
    mutable std::once_flag once_;
    mutable std::string rendered_;
};

using SharedEntryPtr = std::shared_ptr<const SharedEntry>;

}  // namespace rr::server::gateway
