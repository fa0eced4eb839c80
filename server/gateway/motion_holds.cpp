#include "server/gateway/motion_holds.hpp"

#include <algorithm>

namespace rr::server::gateway {

std::string MotionClient::who() const {
    if (user.empty()) return description;
    return user + " (" + description + ")";
}

bool MotionHolds::active(const Holder& h, Time now) const {
    if (h.timed_until && *h.timed_until > now) return true;
    if (!h.untimed.empty()) return true;
    for (const auto& [member, last] : h.streams)
        if (now - last < silence_) return true;
    return false;
}

Result<void> MotionHolds::take(const MotionClient& client, Time now, const std::string& since, std::string_view device) {
    if (holder_ && holder_->client.key == client.key) {
        // The same holder; a newer connection detail (a passthrough session) replaces the old.
        holder_->client.device_session = client.device_session;
        if (client.liveness) holder_->client.liveness = client.liveness;
        return {};
    }
    if (holder_ && active(*holder_, now))
        return fail(MessageErrorType::ObjectLockedError,
                    "motion of " + std::string(device) + " is held by " + holder_->client.who() + " since " + holder_->since +
                        ": try again when its motion ends, or stop the robot (halt)");
    holder_ = Holder{client, since, std::nullopt, {}, {}};
    return {};
}

std::optional<MotionHolds::Time> MotionHolds::timed(Time until) {
    if (!holder_) return std::nullopt;
    const auto before = holder_->timed_until;
    if (!holder_->timed_until || *holder_->timed_until < until) holder_->timed_until = until;
    return before;
}

void MotionHolds::undo_timed(const std::string& key, std::optional<Time> before, Time now) {
    if (!holder_ || holder_->client.key != key) return;
    holder_->timed_until = before;
    if (!active(*holder_, now)) holder_.reset();
}

std::uint64_t MotionHolds::begin_untimed(const std::string& owner, std::string member) {
    const std::uint64_t token = next_token_++;
    if (holder_) holder_->untimed[token] = owner;
    (void)member;
    return token;
}

void MotionHolds::end_untimed(std::uint64_t token) {
    if (holder_) holder_->untimed.erase(token);
}

bool MotionHolds::has_token(std::uint64_t token) const { return holder_ && holder_->untimed.count(token) != 0; }

void MotionHolds::stream_packet(const std::string& member, Time now) {
    if (holder_) holder_->streams[member] = now;
}

void MotionHolds::stopped() { holder_.reset(); }

MotionHolds::Gone MotionHolds::gone(const std::string& owner, Time now) {
    Gone out;
    if (!holder_) return out;
    for (auto it = holder_->untimed.begin(); it != holder_->untimed.end();) {
        if (it->second == owner) {
            out.tokens.push_back(it->first);
            it = holder_->untimed.erase(it);
        } else {
            ++it;
        }
    }
    out.stop = !out.tokens.empty();
    if (holder_->client.owner_key() == owner) {
        // A stream still listed was not reported silent by expire(): its motion may run (the connection
        // can close just as the stream goes quiet, a liveness probe's close after the same bound).
        if (!holder_->streams.empty()) out.stop = true;
        holder_->streams.clear();
        holder_->timed_until.reset();
    }
    if (!active(*holder_, now)) holder_.reset();
    return out;
}

std::vector<std::string> MotionHolds::expire(Time now) {
    std::vector<std::string> silent;
    if (!holder_) return silent;
    for (auto it = holder_->streams.begin(); it != holder_->streams.end();) {
        if (now - it->second >= silence_) {
            silent.push_back(it->first);
            it = holder_->streams.erase(it);
        } else {
            ++it;
        }
    }
    if (holder_->timed_until && *holder_->timed_until <= now) holder_->timed_until.reset();
    if (!active(*holder_, now)) holder_.reset();
    return silent;
}

std::optional<MotionHolds::Time> MotionHolds::next_deadline() const {
    if (!holder_) return std::nullopt;
    std::optional<Time> next = holder_->timed_until;
    for (const auto& [member, last] : holder_->streams) {
        const Time t = last + silence_;
        if (!next || t < *next) next = t;
    }
    return next;
}

const MotionClient* MotionHolds::holder(Time now) const {
    if (!holder_ || !active(*holder_, now)) return nullptr;
    return &holder_->client;
}

const std::string& MotionHolds::since() const noexcept {
    static const std::string none;
    return holder_ ? holder_->since : none;
}

const MotionClient* MotionHolds::probed() const {
    if (!holder_ || (holder_->untimed.empty() && holder_->streams.empty())) return nullptr;
    return &holder_->client;
}

}  // namespace rr::server::gateway
