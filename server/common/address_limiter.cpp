#include "server/common/address_limiter.hpp"

namespace rr::server {

AddressLimiter::Slot::~Slot() {
    if (auto o = owner_.lock()) o->release(address_);
}

std::shared_ptr<AddressLimiter> AddressLimiter::create(std::size_t max_per_address) {
    return std::shared_ptr<AddressLimiter>(new AddressLimiter(max_per_address));
}

std::shared_ptr<AddressLimiter::Slot> AddressLimiter::acquire(const std::string& address) {
    {
        std::lock_guard lock(mutex_);
        auto& n = open_[address];
        if (max_ && n >= max_) {
            ++refused_;
            if (n == 0) open_.erase(address);
            return nullptr;
        }
        ++n;
    }
    return std::make_shared<Slot>(weak_from_this(), address);
}

void AddressLimiter::release(const std::string& address) noexcept {
    std::lock_guard lock(mutex_);
    auto it = open_.find(address);
    if (it == open_.end()) return;
    if (--it->second == 0) open_.erase(it);
}

std::size_t AddressLimiter::count(const std::string& address) const {
    std::lock_guard lock(mutex_);
    auto it = open_.find(address);
    return it == open_.end() ? 0 : it->second;
}

std::size_t AddressLimiter::addresses() const {
    std::lock_guard lock(mutex_);
    return open_.size();
}

std::uint64_t AddressLimiter::refused() const {
    std::lock_guard lock(mutex_);
    return refused_;
}

}  // namespace rr::server
