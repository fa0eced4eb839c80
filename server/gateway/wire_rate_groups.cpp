#include "server/gateway/wire_rate_groups.hpp"

#include <chrono>
#include <utility>
#include <vector>

#include <boost/asio/steady_timer.hpp>

#include "server/gateway/rate_ticker.hpp"

namespace rr::server::gateway {

struct WireRateGroups::Group {
    struct Member {
        std::uint64_t id = 0;
        std::shared_ptr<const OnValue> on_value;  // shared: the copy-on-write member lists copy pointers
    };
    using Members = std::shared_ptr<const std::vector<Member>>;  // copied on write: a hand-out takes a reference

    Group(Key k, RateClock period, const boost::asio::any_io_executor& executor)
        : key(std::move(k)), rate(period), timer(executor) {}

    const Key key;
    std::function<void(std::uint64_t)> unsubscribe;
    std::mutex mutex;  // everything below
    RateWindow rate;
    Members members = std::make_shared<const std::vector<Member>>();  // answered: values go to them
    std::vector<std::pair<Member, Done>> waiting;                     // joined before the wire held
    bool ready = false;  // the upstream subscription holds
    bool ended = false;  // failed, closed by the device, or left by its last member: forgotten
    bool upstream_known = false;
    std::uint64_t upstream_id = 0;
    std::uint64_t seq = 0;   // values offered so far: the newest's place in the group's order
    SharedEntryPtr pending;  // the newest value not handed out yet (waiting for the next window)
    std::uint64_t replaced = 0;  // values replaced since the previous hand-out
    SharedEntryPtr last;     // the newest value, for members joining later
    boost::asio::steady_timer timer;
    bool armed = false;

    void add(std::vector<Member> more) {
        auto next = std::make_shared<std::vector<Member>>(*members);
        for (auto& m : more) next->push_back(std::move(m));
        members = std::move(next);
    }
    bool remove(std::uint64_t id) {
        for (auto it = waiting.begin(); it != waiting.end(); ++it)
            if (it->first.id == id) {
                waiting.erase(it);
                return true;
            }
        auto next = std::make_shared<std::vector<Member>>();
        next->reserve(members->size());
        bool found = false;
        for (const auto& m : *members) {
            if (m.id == id) found = true;
            else next->push_back(m);
        }
        if (found) members = std::move(next);
        return found;
    }
    bool empty() const { return members->empty() && waiting.empty(); }
};

namespace {

// A value to every answered member of a group (outside its locks).
template <class Members>
void hand_out(const Members& members, const SharedEntryPtr& e, std::uint64_t coalesced, std::uint64_t seq,
              std::atomic<std::uint64_t>& handed) {
    handed.fetch_add(members.size(), std::memory_order_relaxed);
    for (const auto& m : members) (*m.on_value)(e, coalesced, seq);
}

}  // namespace

WireRateGroups::~WireRateGroups() {
    std::lock_guard lock(mutex_);
    for (auto& [key, g] : groups_) {
        std::lock_guard glock(g->mutex);
        g->ended = true;
        g->timer.cancel();
    }
}

std::uint64_t WireRateGroups::join(Upstream upstream, RateClock period, OnValue on_value, Done done) {
    std::shared_ptr<Group> g;
    bool create = false, ready_now = false;
    SharedEntryPtr last;
    std::uint64_t id = 0, last_seq = 0;
    auto handler = std::make_shared<const OnValue>(std::move(on_value));
    {
        std::lock_guard lock(mutex_);
        id = next_member_++;
        auto& slot = groups_[Key{upstream.source, upstream.path, upstream.member, period.count()}];
        if (!slot) {
            slot = std::make_shared<Group>(Key{upstream.source, upstream.path, upstream.member, period.count()}, period, executor_);
            slot->unsubscribe = upstream.unsubscribe;
            create = true;
        }
        g = slot;
        members_[id] = g;
        std::lock_guard glock(g->mutex);
        if (g->ready) {
            g->add({Group::Member{id, handler}});
            last = g->last;
            last_seq = g->seq;
            ready_now = true;
        } else {
            g->waiting.emplace_back(Group::Member{id, handler}, std::move(done));
        }
    }
    if (ready_now) {
        if (last) (*handler)(last, 0, last_seq);  // a newer value's hand-out may have reached it already
        if (done) done({});
        return id;
    }
    if (!create) return id;
    // The group's one upstream subscription; `subscribed` may run inside `subscribe`.
    std::weak_ptr<WireRateGroups> weak = weak_from_this();
    std::weak_ptr<Group> wg = g;
    const std::uint64_t up = upstream.subscribe(
        [weak, wg](const SharedEntryPtr& e) {
            auto self = weak.lock();
            auto group = wg.lock();
            if (self && group) self->offer(group, e);
        },
        [weak, wg](Result<void> r) {
            auto self = weak.lock();
            auto group = wg.lock();
            if (self && group) self->subscribed(group, std::move(r));
        });
    bool drop = false;
    {
        std::lock_guard glock(g->mutex);
        g->upstream_id = up;
        g->upstream_known = true;
        drop = g->ended;  // failed, or every member left, before the id was known
    }
    if (drop && g->unsubscribe) g->unsubscribe(up);
    return id;
}

void WireRateGroups::subscribed(const std::shared_ptr<Group>& g, Result<void> r) {
    std::vector<std::pair<Group::Member, Done>> waiting;
    SharedEntryPtr last;
    std::uint64_t last_seq = 0;
    bool unsubscribe = false;
    std::uint64_t up = 0;
    {
        std::lock_guard glock(g->mutex);
        if (g->ended) return;
        waiting.swap(g->waiting);
        if (r) {
            g->ready = true;
            std::vector<Group::Member> joined;
            for (const auto& w : waiting) joined.push_back(w.first);
            g->add(std::move(joined));
            last = g->last;
            last_seq = g->seq;
            g->pending = nullptr;  // `last` goes to every member now
            g->replaced = 0;
        } else {
            g->ended = true;
            unsubscribe = g->upstream_known;
            up = g->upstream_id;
        }
    }
    if (!r) {
        forget(g);
        if (unsubscribe && g->unsubscribe) g->unsubscribe(up);
    }
    for (auto& [member, done] : waiting) {
        if (r && last) (*member.on_value)(last, 0, last_seq);  // (a newer one may have reached it already)
        if (done) done(r);
    }
}

void WireRateGroups::offer(const std::shared_ptr<Group>& g, const SharedEntryPtr& e) {
    if (e->entry().entry_type == MessageEntryType::WireClosed) {
        // The wire and its upstream subscription are gone: every member is told, the group forgotten.
        Group::Members members;
        std::vector<std::pair<Group::Member, Done>> waiting;
        std::uint64_t seq = 0;
        {
            std::lock_guard glock(g->mutex);
            if (g->ended) return;
            g->ended = true;
            seq = ++g->seq;
            members = g->members;
            waiting.swap(g->waiting);
            g->timer.cancel();
        }
        forget(g);
        for (const auto& m : *members) (*m.on_value)(e, 0, seq);
        for (auto& [member, done] : waiting)
            if (done) done(fail(MessageErrorType::ConnectionError, "wire closed by the device"));
        return;
    }
    offers_.fetch_add(1, std::memory_order_relaxed);
    Group::Members members;
    std::uint64_t replaced = 0, seq = 0;
    {
        std::lock_guard glock(g->mutex);
        if (g->ended) return;
        if (g->last && e->arrival() <= g->last->arrival()) {
            // the wire's newest, handed to the group's upstream subscription on joining, came after a
            // newer value: replaced unseen
            coalesced_.fetch_add(1, std::memory_order_relaxed);
            return;
        }
        g->last = e;
        seq = ++g->seq;
        const RateClock now = rate_clock_now();
        if (g->ready && g->rate.open(now)) {
            g->rate.sent(now);
            if (g->pending) {  // a new window began before its timer handed the waiting value out
                ++g->replaced;
                coalesced_.fetch_add(1, std::memory_order_relaxed);
                g->pending = nullptr;
            }
            replaced = std::exchange(g->replaced, 0);
            members = g->members;
        } else {
            if (g->pending) {  // newest wins
                ++g->replaced;
                coalesced_.fetch_add(1, std::memory_order_relaxed);
            }
            g->pending = e;  // before the wire holds, `last` goes to the members that wait
            if (g->ready) arm(g);
        }
    }
    if (members) hand_out(*members, e, replaced, seq, handed_);
}

void WireRateGroups::arm(const std::shared_ptr<Group>& g) {
    if (g->armed) return;
    g->armed = true;
    g->timer.expires_at(std::chrono::steady_clock::time_point(
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(g->rate.next_open())));
    std::weak_ptr<WireRateGroups> weak = weak_from_this();
    std::weak_ptr<Group> wg = g;
    g->timer.async_wait([weak, wg](boost::system::error_code ec) {
        if (ec) return;
        auto self = weak.lock();
        auto group = wg.lock();
        if (self && group) self->on_window(group);
    });
}

void WireRateGroups::on_window(const std::shared_ptr<Group>& g) {
    Group::Members members;
    SharedEntryPtr e;
    std::uint64_t replaced = 0, seq = 0;
    {
        std::lock_guard glock(g->mutex);
        g->armed = false;
        if (g->ended || !g->pending) return;
        const RateClock now = rate_clock_now();
        if (!g->rate.open(now)) {  // not expected (a timer never fires early); wait on
            arm(g);
            return;
        }
        g->rate.sent(now);
        e = std::exchange(g->pending, nullptr);
        seq = g->seq;  // `pending` is always the newest value
        replaced = std::exchange(g->replaced, 0);
        members = g->members;
    }
    hand_out(*members, e, replaced, seq, handed_);
}

void WireRateGroups::leave(std::uint64_t member) {
    std::shared_ptr<Group> g;
    bool unsubscribe = false;
    std::uint64_t up = 0;
    {
        std::lock_guard lock(mutex_);
        auto it = members_.find(member);
        if (it == members_.end()) return;
        g = std::move(it->second);
        members_.erase(it);
        std::lock_guard glock(g->mutex);
        g->remove(member);
        if (!g->ended && g->empty()) {
            g->ended = true;
            g->timer.cancel();
            if (auto gi = groups_.find(g->key); gi != groups_.end() && gi->second == g) groups_.erase(gi);
            unsubscribe = g->upstream_known;  // else join() unsubscribes once the id is known
            up = g->upstream_id;
        }
    }
    if (unsubscribe && g->unsubscribe) g->unsubscribe(up);
}

void WireRateGroups::forget(const std::shared_ptr<Group>& g) {
    std::lock_guard lock(mutex_);
    if (auto gi = groups_.find(g->key); gi != groups_.end() && gi->second == g) groups_.erase(gi);
    for (auto it = members_.begin(); it != members_.end();) it = it->second == g ? members_.erase(it) : std::next(it);
}

std::size_t WireRateGroups::groups() const {
    std::lock_guard lock(mutex_);
    return groups_.size();
}

std::uint64_t WireRateGroups::offers() const noexcept { return offers_.load(std::memory_order_relaxed); }
std::uint64_t WireRateGroups::handed() const noexcept { return handed_.load(std::memory_order_relaxed); }
std::uint64_t WireRateGroups::coalesced() const noexcept { return coalesced_.load(std::memory_order_relaxed); }

}  // namespace rr::server::gateway
