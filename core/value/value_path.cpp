#include "core/value/value_path.hpp"

namespace rr {

std::string ValuePath::to_string() const {
    std::string s;
    for (std::size_t i = 0; i < segs_.size(); ++i) {
        const Seg& g = segs_[i];
        switch (g.kind) {
            case Seg::name:
                if (i == 0 && g.text.empty()) {
                    s += "value";
                } else {
                    if (i) s += '.';
                    s += g.text;
                }
                break;
            case Seg::index: s += "[" + std::to_string(g.number) + "]"; break;
            case Seg::key:
                s += "[\"";
                s += g.text;
                s += "\"]";
                break;
        }
    }
    return s;
}

Unexpected ValuePath::error(MessageErrorType type, std::string_view message) const {
    return fail(type, std::string(message) + " at \"" + to_string() + "\"");
}

}  // namespace rr
