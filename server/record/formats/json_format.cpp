// The `json` format (json_format.hpp): its channel mapping, and its encoder writing one message per
// entry on each member's channel.
#include "server/record/formats/json_format.hpp"

#include <nlohmann/json.hpp>

#include "server/gateway/json_push.hpp"
#include "server/record/formats/formats.hpp"
#include "server/record/json_schema.hpp"

namespace rr::server::record {
namespace {

// Null members left out of every object (see json_format.hpp); nulls inside arrays stay (removing them
// would shift the indices).
void drop_null_members(nlohmann::json& j) {
    if (j.is_object()) {
        for (auto it = j.begin(); it != j.end();) {
            if (it->is_null()) it = j.erase(it);
            else drop_null_members(*it++);
        }
    } else if (j.is_array()) {
        for (auto& x : j) drop_null_members(x);
    }
}

std::string without_null_members(std::string text) {
    // The common case (a text plan's, null members already left out): nothing to parse again.
    if (text.find("null") == std::string::npos) return text;
    auto j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded()) return text;
    drop_null_members(j);
    return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// The json message of a pipe packet or a polled property: {"value": …}, or {"error": …} for no value or
// one that does not fit. Written straight from the element, null members left out, when the member's
// type has a text plan (core/json/element_json_plan.hpp): a 320x240 camera frame is one pass over its
// bytes, not a tree of 230,400 numbers built, walked for nulls and dumped; through element_json
// otherwise and for errors.
std::string value_message_text(const gateway::JsonApi& api, const MessageElement* el, const gateway::MemberTarget& t) {
    if (el && t.types && t.service) {
        if (const auto* plan = t.types->json_text_plan(t.member->type, t.context(), api.options().limits)) {
            std::string out = "{\"value\":";
            if (plan->append(out, *el, /*omit_null_members=*/true)) {
                out += '}';
                return without_null_members(std::move(out));
            }
        }
    }
    nlohmann::json body = nlohmann::json::object();
    if (!el) {
        body["error"] = {{"message", "no value"}};
    } else {
        auto j = api.element_json(*el, t.member->type, t);
        if (j) body["value"] = std::move(j.value);
        else body["error"] = {{"name", j.error->name}, {"message", j.error->message}};
    }
    drop_null_members(body);
    return body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

class JsonEncoder : public FormatEncoder {
public:
    explicit JsonEncoder(const FormatContext& context) : context_(context) {}

    Result<void> open_file(FormatFile& file) override {
        channels_.clear();
        for (const auto& m : context_.members) {
            const auto c = json_channel(m);
            auto sid = file.add_schema(c.schema_name, c.schema_encoding, c.schema);
            if (!sid) return sid.take_error();
            auto cid = file.add_channel(*sid, c.topic, c.message_encoding, c.metadata);
            if (!cid) return cid.take_error();
            channels_.push_back(*cid);
        }
        return {};
    }

    Result<void> write(const RecordedEntry& e, MessageOut& out) override {
        return out.write(channels_[e.member], json_message(context_.api, context_.members[e.member], e.entry));
    }

private:
    const FormatContext& context_;
    std::vector<std::uint16_t> channels_;  // per member
};

class JsonFormat : public RecordingFormat {
public:
    std::string_view name() const noexcept override { return "json"; }
    std::unique_ptr<FormatEncoder> encoder(const FormatContext& context) const override { return std::make_unique<JsonEncoder>(context); }
};

}  // namespace

MappedChannel json_channel(const RecordedMember& m) {
    const auto& t = *m.target;
    const std::string title = t.object_type + "." + t.member->name;
    nlohmann::json schema;
    switch (m.kind) {
        case RecordedKind::wire: schema = wire_message_schema(t.member->type, t.types->set(), t.context(), title); break;
        case RecordedKind::event: schema = event_message_schema(*t.member, t.types->set(), t.context(), title); break;
        case RecordedKind::pipe:
        case RecordedKind::property: schema = value_message_schema(t.member->type, t.types->set(), t.context(), title); break;
    }
    return MappedChannel{m.topic, "json", title, "jsonschema", schema.dump(), m.metadata};
}

std::string json_message(const gateway::JsonApi& api, const RecordedMember& m, const gateway::SharedEntry& shared) {
    const auto& t = *m.target;
    const MessageEntry& entry = shared.entry();
    switch (m.kind) {
        case RecordedKind::wire:
        case RecordedKind::event: {
            // The JSON sockets' body of this entry (json_socket.cpp renders it the same way), made once for
            // all of them and this channel; when it holds a null member, the text without them.
            const std::string& body = shared.rendered([&](const MessageEntry& e) {
                return m.kind == RecordedKind::wire ? gateway::wire_push_text(api, e, t) : gateway::event_push_text(api, e, t);
            });
            if (body.find("null") == std::string::npos) return body;
            std::string text = m.kind == RecordedKind::wire ? gateway::wire_push_text(api, entry, t, /*omit_null_members=*/true)
                                                            : gateway::event_push_text(api, entry, t, /*omit_null_members=*/true);
            return without_null_members(std::move(text));
        }
        case RecordedKind::pipe: return value_message_text(api, entry.elements.empty() ? nullptr : &entry.elements[0], t);
        case RecordedKind::property: return value_message_text(api, entry.find("value"), t);
    }
    return {};
}

std::shared_ptr<const RecordingFormat> json_format() { return std::make_shared<JsonFormat>(); }

}  // namespace rr::server::record
