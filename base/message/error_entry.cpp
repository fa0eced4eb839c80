#include "base/message/error_entry.hpp"

#include <utility>

namespace rr {
namespace {

std::optional<std::string> string_value(const MessageEntry& entry, std::string_view name) {
    const MessageElement* e = entry.find(name);
    if (!e || e->type != DataTypes::string_t) return std::nullopt;
    // A char view of the payload bytes: aliasing-safe, no integer is read through the cast.
    return std::string(reinterpret_cast<const char*>(e->data.data()), e->data.size());
}

}  // namespace

MessageElement make_string_element(std::string name, std::string_view text) {
    MessageElement e;
    e.name = std::move(name);
    e.type = DataTypes::string_t;
    if (!text.empty()) e.data = SharedBytes::copy_of(text.data(), text.size());
    return e;
}

void set_entry_error(MessageEntry& entry, const RRError& error) {
    entry.error = error.type;
    entry.elements.clear();
    std::string_view name = error.name.empty() ? error_name(error.type) : std::string_view(error.name);
    entry.elements.push_back(make_string_element("errorname", name));
    entry.elements.push_back(make_string_element("errorstring", error.message));
    if (!error.sub_name.empty()) entry.elements.push_back(make_string_element("errorsubname", error.sub_name));
    if (error.param) {
        MessageElement& p = entry.elements.emplace_back(*error.param);
        p.name = "errorparam";
    }
}

std::optional<RRError> entry_error(const MessageEntry& entry) {
    if (entry.error == MessageErrorType::None) return std::nullopt;
    RRError e;
    e.type = entry.error;
    auto name = string_value(entry, "errorname");
    e.name = name ? std::move(*name) : std::string(error_name(entry.error));
    e.message = string_value(entry, "errorstring").value_or(std::string());
    e.sub_name = string_value(entry, "errorsubname").value_or(std::string());
    if (const MessageElement* p = entry.find("errorparam")) e.param = std::make_shared<const MessageElement>(*p);
    return e;
}

MessageEntry reply_to(const MessageEntry& request) {
    MessageEntry r;
    r.entry_type = static_cast<MessageEntryType>(static_cast<std::uint16_t>(request.entry_type) + 1);
    r.service_path = request.service_path;
    r.member_name = request.member_name;
    r.request_id = request.request_id;
    return r;
}

MessageEntry relayed_reply(MessageEntry header, Result<MessageEntry> result) {
    if (!result) {
        set_entry_error(header, result.error());
    } else {
        header.error = result->error;
        header.elements = std::move(result->elements);
    }
    return header;
}

}  // namespace rr
