// One upstream wire value or event as the gateway's subscribers see it: a single shared copy for all
// of them, native clients and JSON API sockets alike. The native clients' messages copy its encoded
// bytes (EncodedEntry: encoded once per message format); the JSON sockets share one cached rendering (of each form: text, binary) made by
// the first subscriber that needs it, so a value fanned out to N WebSocket clients is converted to JSON
// once, not N times.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "base/codec/shared_bytes.hpp"
#include "base/message/encoded_entry.hpp"
#include "base/message/message.hpp"

namespace rr::server::gateway {

class SharedEntry : public EncodedEntry {
public:
    explicit SharedEntry(MessageEntry entry) : EncodedEntry(std::move(entry)), arrival_(next_arrival()) {}

    /// Its place in the order the gateway made values in (process-wide, increasing, never 0). A device
    /// connection delivers a wire's values in order, so of two values of one wire the one with the larger
    /// arrival is the newer: a subscriber handed the wire's newest value on joining, while a newer one is
    /// fanned out to it, keeps the newer (the ordering native clients get from the packets' timestamps).
    std::uint64_t arrival() const noexcept { return arrival_; }

    /// The text `render(entry())` returns, computed once; callers on other threads wait for it. Every
    /// subscriber must pass an equivalent `render` (the same conversion for the same member).
    template <class Render>
    const std::string& rendered(Render&& render) const {
        std::call_once(once_, [&] { rendered_ = std::forward<Render>(render)(entry()); });
        return rendered_;
    }

    /// Like rendered(), for the subscribers of binary pushes (binary_push.hpp): the body's text with
    /// "$binary" references, and the arrays they refer to.
    struct BinaryRendering {
        std::string body;
        /// The binary push's arrays part (binary_push_arrays), written as it is for every subscriber;
        /// null when the body refers to no arrays (a text push).
        std::shared_ptr<const std::string> arrays;
    };
    template <class Render>
    const BinaryRendering& rendered_binary(Render&& render) const {
        std::call_once(binary_once_, [&] { binary_ = std::forward<Render>(render)(entry()); });
        return binary_;
    }

private:
    static std::uint64_t next_arrival() noexcept {
        static std::atomic<std::uint64_t> counter{0};
        return counter.fetch_add(1, std::memory_order_relaxed) + 1;
    }

    std::uint64_t arrival_;
    mutable std::once_flag once_, binary_once_;
    mutable std::string rendered_;
    mutable BinaryRendering binary_;
};

using SharedEntryPtr = std::shared_ptr<const SharedEntry>;

}  // namespace rr::server::gateway
