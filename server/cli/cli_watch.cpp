#include "server/cli/cli_watch.hpp"

#include <chrono>
#include <condition_variable>
#include <deque>
#include <mutex>

#include "core/json/value_json.hpp"

namespace rr::cli {

namespace {

using namespace std::chrono_literals;
using robdef::MemberKind;
using Clock = std::chrono::steady_clock;

constexpr auto kPoll = 100ms;  // how often the loop looks at the stop flag

// When a watch ends: stop flag, --count, --seconds, or nobody reads the output any more
// (`rr watch … | head -1`: SIGPIPE is ignored, the failed write marks the stream bad).
struct StopRule {
    const std::atomic<bool>& stop;
    const std::ostream& out;
    std::optional<std::uint64_t> count;
    std::optional<Clock::time_point> deadline;
    std::uint64_t printed = 0;

    bool done() const {
        return stop.load() || !out.good() || (count && printed >= *count) || (deadline && Clock::now() >= *deadline);
    }
};

// Lines made on the strand (event handler), printed by the main thread.
struct LineQueue {
    std::mutex mutex;
    std::condition_variable cv;
    std::deque<std::string> lines;
    std::optional<RRError> error;

    void push(std::string line) {
        std::lock_guard lock(mutex);
        lines.push_back(std::move(line));
        cv.notify_one();
    }
    void fail(RRError e) {
        std::lock_guard lock(mutex);
        if (!error) error = std::move(e);
        cv.notify_one();
    }
};

Failure rr_failure(RRError e) { return Failure{ExitCode::rr_error, std::move(e)}; }

void print(std::ostream& out, const nlohmann::json& j, StopRule& rule) {
    out << json_line(j) << std::endl;
    ++rule.printed;
}

std::optional<Failure> watch_wire(Target& t, const MemberInfo& m, std::ostream& out, StopRule& rule) {
    auto w = t.object.wire_connect(m.def.name);
    if (!w) return rr_failure(w.error());
    if (!w->info().readable) {
        (void)w->close();
        return rr_failure(make_error(MessageErrorType::WriteOnlyMember, "wire " + m.def.name + " is write-only"));
    }
    // Values are numbered as they arrive; wait for the one after the last printed. The time stamp
    // check skips a value seen twice when the client fell more than 256 values behind.
    std::uint64_t seen = 0;
    std::optional<TimeSpec> last;
    std::optional<Failure> result;
    while (!rule.done()) {
        auto v = w->wait_value([&](const WireValue& x) { return !last || !(x.timestamp == *last); }, kPoll, seen);
        if (!v) {
            if (v.error().type == MessageErrorType::OperationTimeout) continue;
            result = rr_failure(v.error());
            break;
        }
        ++seen;
        last = v->timestamp;
        auto j = to_json(*t.client, v->value, m.def.type, m.service);
        if (!j) {
            result = rr_failure(j.error());
            break;
        }
        print(out, *j, rule);
    }
    (void)w->close();
    return result;
}

std::optional<Failure> watch_pipe(Target& t, const MemberInfo& m, std::ostream& out, StopRule& rule) {
    auto p = t.object.pipe_connect(m.def.name, -1);
    if (!p) return rr_failure(p.error());
    std::optional<Failure> result;
    while (!rule.done()) {
        auto v = p->receive(kPoll);
        if (!v) {
            if (v.error().type == MessageErrorType::OperationTimeout) continue;
            result = rr_failure(v.error());
            break;
        }
        auto j = to_json(*t.client, *v, m.def.type, m.service);
        if (!j) {
            result = rr_failure(j.error());
            break;
        }
        print(out, *j, rule);
    }
    if (!p->is_closed()) (void)p->close();
    return result;
}

std::optional<Failure> watch_event(Target& t, const MemberInfo& m, std::ostream& out, StopRule& rule) {
    auto q = std::make_shared<LineQueue>();
    client::Client* c = t.client.get();
    const auto params = m.def.parameters;
    const std::string service = m.service;
    // The handler runs on the strand; run() executes inline there, with the definitions at hand.
    auto sub = t.object.subscribe(m.def.name, [q, c, params, service](const std::string&, std::vector<Value>& args) {
        c->run([&](ClientContext& ctx, MonoTime) {
            nlohmann::json line = nlohmann::json::object();
            for (std::size_t i = 0; i < params.size() && i < args.size(); ++i) {
                auto j = value_to_json(args[i], params[i], ctx.definitions(), service);
                if (!j) return q->fail(j.error());
                line[params[i].name] = std::move(*j);
            }
            q->push(json_line(line));
        });
    });
    if (!sub) return rr_failure(sub.error());
    t.client->set_closed_handler([q](const RRError& e) { q->fail(e); });
    std::optional<Failure> result;
    while (!rule.done()) {
        std::unique_lock lock(q->mutex);
        q->cv.wait_for(lock, kPoll, [&] { return !q->lines.empty() || q->error; });
        while (!q->lines.empty() && !(rule.count && rule.printed >= *rule.count)) {
            out << q->lines.front() << std::endl;
            q->lines.pop_front();
            ++rule.printed;
        }
        if (q->error && !rule.done()) {
            result = rr_failure(*q->error);
            break;
        }
    }
    t.object.unsubscribe(*sub);
    return result;
}

}  // namespace

std::optional<Failure> run_watch(const CommandLine& cl, Target& t, std::ostream& out, const std::atomic<bool>& stop) {
    auto m = member_info(t.object, *cl.member);
    if (!m) return rr_failure(m.error());
    StopRule rule{stop, out, cl.count, std::nullopt};
    if (cl.seconds)
        rule.deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(*cl.seconds));
    switch (m->def.kind) {
        case MemberKind::wire: return watch_wire(t, *m, out, rule);
        case MemberKind::pipe: return watch_pipe(t, *m, out, rule);
        case MemberKind::event: return watch_event(t, *m, out, rule);
        default:
            return rr_failure(make_error(MessageErrorType::InvalidOperation,
                                         *cl.member + " is " + robdef::with_article(robdef::member_kind_keyword(m->def.kind)) +
                                             "; rr watch streams wires, events and pipes"));
    }
}

}  // namespace rr::cli
