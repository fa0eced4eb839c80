// An entry-level test service used by server tests: property `x`, function `add`, `fire` (event +
// wire packet to every connected wire), callback round trip through `callme`, and a wire `w`.
#pragma once

#include <atomic>
#include <mutex>
#include <vector>

#include <catch2/catch.hpp>

#include "core/session/elements.hpp"
#include "core/value/timespec.hpp"
#include "server/node/service.hpp"

namespace rr::server::testing {

constexpr const char* kDef = "service example.rawtest\n\nstdver 0.10\n\nobject Obj\n    property double x\n"
                             "    function int32 add(int32 a, int32 b)\n    event changed(double v)\n"
                             "    function void fire()\n    callback double cb(double v)\n    function double callme(double v)\n"
                             "    wire double w [readonly]\nend\n";

class RawTestService : public Service {
public:
    const std::string& name() const override { return name_; }
    std::vector<std::string> service_definitions() const override { return {kDef}; }
    std::optional<std::string> service_definition(std::string_view type) const override {
        if (type == "example.rawtest") return std::string(kDef);
        return std::nullopt;
    }
    ObjectTypeInfo root_type() const override { return {"example.rawtest.Obj", {}}; }
    void object_type(const SessionRef&, const std::string& path, std::function<void(Result<ObjectTypeInfo>)> done) override {
        if (path == "svc") done(root_type());
        else done(fail(MessageErrorType::ObjectNotFound, "Object not found"));
    }
    void on_session_open(const SessionRef& s) override { opened++; (void)s; }
    void on_session_close(const SessionRef& s) override { closed++; (void)s; }

    void handle_entry(const SessionRef& session, MessageEntry&& e, Responder responder) override {
        if (e.entry_type == MessageEntryType::WireConnectReq && e.member_name == "w") {
            {
                std::lock_guard lock(mutex);
                wire_sessions.push_back(session);
            }
            responder.respond(MessageEntry{});
            return;
        }
        if (e.entry_type == MessageEntryType::WireDisconnectReq && e.member_name == "w") {
            {
                std::lock_guard lock(mutex);
                std::erase(wire_sessions, session);
            }
            responder.respond(MessageEntry{});
            return;
        }
        if (e.entry_type == MessageEntryType::PropertyGetReq && e.member_name == "x") {
            MessageEntry r;
            r.elements.push_back(make_scalar_element("value", 42.5));
            responder.respond(std::move(r));
            return;
        }
        if (e.entry_type == MessageEntryType::FunctionCallReq && e.member_name == "add") {
            std::int32_t a = 0, b = 0;
            const auto* ea = e.find("a");
            const auto* eb = e.find("b");
            if (!ea || !eb || !read_scalar(*ea, a) || !read_scalar(*eb, b)) {
                responder.fail(make_error(MessageErrorType::DataTypeError, "add takes two int32"));
                return;
            }
            MessageEntry r;
            r.elements.push_back(make_scalar_element<std::int32_t>("return", a + b));
            responder.respond(std::move(r));
            return;
        }
        if (e.entry_type == MessageEntryType::FunctionCallReq && e.member_name == "fire") {
            MessageEntry ev;
            ev.entry_type = MessageEntryType::EventReq;
            ev.service_path = "svc";
            ev.member_name = "changed";
            ev.elements.push_back(make_scalar_element("v", 7.0));
            REQUIRE(session.send(std::move(ev)));
            std::vector<SessionRef> wires;
            {
                std::lock_guard lock(mutex);
                wires = wire_sessions;
            }
            for (const auto& w : wires) {
                MessageEntry p;
                p.entry_type = MessageEntryType::WirePacket;
                p.service_path = "svc";
                p.member_name = "w";
                p.metadata = "unreliable\n";
                p.elements.push_back(pack_timespec(TimeSpec{1700000000, 5}, "packettime"));
                p.elements.push_back(make_scalar_element("packet", 9.5));
                (void)w.send_wire_packet(std::move(p));
            }
            MessageEntry r;
            r.elements.push_back(make_scalar_element<std::int32_t>("return", 0));
            responder.respond(std::move(r));
            return;
        }
        if (e.entry_type == MessageEntryType::FunctionCallReq && e.member_name == "callme") {
            double v = 0;
            if (const auto* ev = e.find("v")) read_scalar(*ev, v);
            MessageEntry call;
            call.entry_type = MessageEntryType::CallbackCallReq;
            call.service_path = "svc";
            call.member_name = "cb";
            call.elements.push_back(make_scalar_element("v", v));
            auto shared = std::make_shared<Responder>(std::move(responder));
            session.request(std::move(call), [shared](Result<MessageEntry> reply) {
                if (!reply) {
                    shared->fail(reply.error());
                    return;
                }
                double ret = 0;
                const auto* el = reply->find("return");
                if (!el || !read_scalar(*el, ret)) {
                    shared->fail(make_error(MessageErrorType::DataTypeError, "callback returned no double"));
                    return;
                }
                MessageEntry r;
                r.elements.push_back(make_scalar_element("return", ret));
                shared->respond(std::move(r));
            });
            return;
        }
        responder.fail(make_error(MessageErrorType::MemberNotFound, "Member \"" + e.member_name + "\" not found"));
    }

    std::atomic<int> opened{0}, closed{0};
    std::mutex mutex;
    std::vector<SessionRef> wire_sessions;

private:
    std::string name_ = "svc";
};

/// A PropertyGetReq for RawTestService's `x` with `padding` bytes of uint8 array element: a request of
/// about that size (message-size limit tests).
inline MessageEntry padded_get(std::size_t padding) {
    MessageEntry e;
    e.entry_type = MessageEntryType::PropertyGetReq;
    e.service_path = "svc";
    e.member_name = "x";
    std::vector<std::uint8_t> pad(padding, 0x33);
    e.elements.push_back(make_array_element("padding", std::span<const std::uint8_t>(pad)));
    return e;
}

}  // namespace rr::server::testing
