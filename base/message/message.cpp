#include "base/message/message.hpp"

namespace rr {

std::uint32_t MessageElement::data_count() const noexcept {
    if (is_nested(type)) return static_cast<std::uint32_t>(elements.size());
    auto size = data_type_size(type);
    return size ? static_cast<std::uint32_t>(data.size() / size) : 0;
}

const MessageElement* MessageElement::find(std::string_view n) const noexcept {
    for (const auto& e : elements)
        if (!e.number && e.name == n) return &e;
    return nullptr;
}

const MessageElement* MessageEntry::find(std::string_view n) const noexcept {
    for (const auto& e : elements)
        if (!e.number && e.name == n) return &e;
    return nullptr;
}

}  // namespace rr
