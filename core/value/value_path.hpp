// ValuePath: where in a value tree a pack/unpack/JSON step is, for error messages such as
//   DataTypeError: expected double[3], got 2 items at "pose.position"
// Segments are pushed and popped as the walk descends; the text is only built when an error is made,
// so the happy path costs one small vector push per level.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "base/error/rr_error.hpp"

namespace rr {

class ValuePath {
public:
    explicit ValuePath(std::string_view root) { push_name(root); }

    /// `name` must outlive its segment (definition member names, element names and map keys do).
    void push_name(std::string_view name) { segs_.push_back({name, 0, Seg::name}); }
    void push_index(std::int64_t i) { segs_.push_back({{}, i, Seg::index}); }
    void push_key(std::string_view key) { segs_.push_back({key, 0, Seg::key}); }
    void pop() { segs_.pop_back(); }
    std::size_t depth() const noexcept { return segs_.size(); }

    /// `a.b[3]["key"].c`; "value" when the root name is empty.
    std::string to_string() const;

    /// An error whose message ends with ` at "<path>"`.
    Unexpected error(MessageErrorType type, std::string_view message) const;

private:
    struct Seg {
        enum Kind : std::uint8_t { name, index, key };
        std::string_view text;
        std::int64_t number;
        Kind kind;
    };
    std::vector<Seg> segs_;
};

/// Pops the segment pushed by its creator when leaving scope.
class PathScope {
public:
    PathScope(ValuePath& p, std::string_view name) : p_(p) { p_.push_name(name); }
    PathScope(ValuePath& p, std::int64_t index) : p_(p) { p_.push_index(index); }
    struct Key {
        std::string_view key;
    };
    PathScope(ValuePath& p, Key k) : p_(p) { p_.push_key(k.key); }
    ~PathScope() { p_.pop(); }
    PathScope(const PathScope&) = delete;
    PathScope& operator=(const PathScope&) = delete;

private:
    ValuePath& p_;
};

}  // namespace rr
