// AddressLimiter: counts open connections per client address and refuses one over the limit
// (docs/security.md §Connection limits). Sans-IO: addresses are strings the caller gives (the peer's
// IP address without port); thread-safe (the gateway accepts on several threads).
//
// acquire() returns a Slot that holds the address's count until it is destroyed, so a connection keeps
// its slot by owning it and gives it back however it ends.
#pragma once

#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

namespace rr::server {

class AddressLimiter : public std::enable_shared_from_this<AddressLimiter> {
public:
    /// Holds one connection's place in its address's count; releases it when destroyed.
    class Slot {
    public:
        Slot(std::weak_ptr<AddressLimiter> owner, std::string address) noexcept
            : owner_(std::move(owner)), address_(std::move(address)) {}
        ~Slot();
        Slot(const Slot&) = delete;
        Slot& operator=(const Slot&) = delete;
        const std::string& address() const noexcept { return address_; }

    private:
        std::weak_ptr<AddressLimiter> owner_;
        std::string address_;
    };

    /// max_per_address: open connections allowed per address (0 = unlimited).
    static std::shared_ptr<AddressLimiter> create(std::size_t max_per_address);

    /// A slot for one more connection from `address`, or nullptr when the address already has
    /// max_per_address open (the caller refuses the connection; refused() counts it).
    std::shared_ptr<Slot> acquire(const std::string& address);

    /// Open connections from `address` now.
    std::size_t count(const std::string& address) const;
    /// Addresses with at least one open connection.
    std::size_t addresses() const;
    /// Connections refused so far (for /metrics).
    std::uint64_t refused() const;
    std::size_t max_per_address() const noexcept { return max_; }

private:
    explicit AddressLimiter(std::size_t max) : max_(max) {}
    void release(const std::string& address) noexcept;

    const std::size_t max_;
    mutable std::mutex mutex_;
    std::unordered_map<std::string, std::size_t> open_;
    std::uint64_t refused_ = 0;
};

}  // namespace rr::server
