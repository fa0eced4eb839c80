// Selecting discovered services, as the official ServiceSubscriptionFilter does (CORE Subscription.cpp
// ServiceSubscription_FilterService and ServiceSubscriptionFilterAttributeGroup):
//
//   service types   the root object type or one of the types it implements is in the list (empty = any);
//                   an unqualified implemented type (CORE reports `implements Base` of the root's own
//                   service as "Base") also counts as qualified with the root's service name
//   nodes           any entry matches: NodeID and/or NodeName (an entry with neither matches everything)
//   service names   the service's name is in the list (empty = any)
//   transports      URL schemes; the service's URLs are narrowed to them; when none is left the node's
//                   announced URLs of those schemes are used with the service name put in (CORE does)
//   attributes      per attribute name, a group of values combined with OR/AND/NOR/NAND (nested
//                   groups allowed); the per-name results are combined with `attributes_operation`
//                   (default AND). A string attribute is split at ',' first (CORE's default); a list
//                   matches when an item matches; a string map by name and value. A missing attribute
//                   is an empty list of values.
//   max count       the most services a subscription takes at once (0 = unlimited): applied by the
//                   subscriber, which knows what it already holds.
//
// Regular-expression values are matched by a function the caller supplies (core has no exceptions to
// survive a bad pattern; the server compiles std::regex and passes a matcher).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/discovery/discovery_packet.hpp"
#include "core/discovery/service_info.hpp"

namespace rr::discovery {

enum class FilterOperation : std::uint8_t { op_or, op_and, op_nor, op_nand };

/// "or", "and", "nor", "nand" (any case) → the operation.
std::optional<FilterOperation> parse_filter_operation(std::string_view text);

struct FilterAttribute {
    std::string name;   ///< "" = any name (for string maps); a non-empty name never matches a plain string
    std::string value;  ///< exact value, unless `matcher` is set
    std::function<bool(std::string_view)> matcher;  ///< regex (or other) match of the value
    std::string pattern;  ///< the matcher's source text, for display

    bool matches(std::string_view value) const;
    bool matches(std::string_view name, std::string_view value) const;
};

struct FilterAttributeGroup {
    FilterOperation operation = FilterOperation::op_or;
    std::vector<FilterAttribute> attributes;
    std::vector<FilterAttributeGroup> groups;
    bool split_string = true;
    char delimiter = ',';

    /// Matches an attribute value (string, list of strings, string map of strings; null = absent).
    bool matches(const Value* value) const;
    bool matches_strings(const std::vector<std::string_view>& values) const;
    bool matches_pairs(const std::vector<std::pair<std::string_view, std::string_view>>& pairs) const;
};

struct FilterNode {
    NodeID node_id;         ///< all-zero: any
    std::string node_name;  ///< "": any
};

struct ServiceFilter {
    std::vector<std::string> service_types;
    std::vector<FilterNode> nodes;
    std::vector<std::string> service_names;
    std::vector<std::string> transport_schemes;
    std::map<std::string, FilterAttributeGroup> attributes;
    FilterOperation attributes_operation = FilterOperation::op_and;
    std::uint32_t max_count = 0;
};

/// A service the filter selected.
struct FilterMatch {
    std::string client_service_type;  ///< the listed type it matched (root type when no types are listed)
    std::vector<std::string> urls;    ///< URLs to connect with (scheme-filtered)
};

/// Applies `filter` to one service. `node_urls` are the node's announced URLs (for the transport
/// fallback). nullopt when the service is not selected or no URL is left.
std::optional<FilterMatch> match_service(const ServiceFilter& filter, const ServiceInfo2& info,
                                         const std::vector<std::string>& node_urls = {});

}  // namespace rr::discovery
