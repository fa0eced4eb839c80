// JSON text written straight from a message element of any robdef value type the gateway pushes
// often: the same text as json_text(value_to_json(unpack_value(…))) (nlohmann's compact dump, keys in
// its sorted order), without the Value and nlohmann::json trees in between (issue 14).
//
// A Plan is compiled once per type (named types resolved, fields sorted as nlohmann sorts them, pod
// plans and namedarray offsets worked out) and then renders any number of elements. It writes itself:
//   numeric scalars, T[], T[N], T[N-], T[*] and T[N,M] (element_json_text.hpp for the numbers)
//   string, enum, void
//   struct (recursive ones included), pod and namedarray scalars and 1-D arrays, pod fields of
//   every kind (multi-dim ones too)
//   T{list}, T{int32}, T{string}
// and hands any other part (varvalue, multi-dim pod and namedarray arrays, a definition it does not
// take, such as one with two fields of one name) to the general path for that part alone, so that a
// struct with a `varvalue{string} extended` field still has its other fields written directly. A type
// with nothing to write directly gets no plan (compile() gives nullptr). append() declines any element
// the general path would refuse (wrong element type or type name, missing field, wrong count,
// misnumbered item, duplicate map key, invalid UTF-8, nesting deeper than Limits::max_nesting_depth):
// the caller's general path then words the error. The direct text never differs from the general
// path's, and never stands where the general path reports an error.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "base/codec/limits.hpp"
#include "base/message/message.hpp"
#include "robdef/service_definition.hpp"
#include "robdef/type_lookup.hpp"

namespace rr::element_json_text {

class Plan {
public:
    /// The plan of robdef type `type` (named types through `lookup`, unqualified ones in
    /// `context_service`), or nullptr when it would write nothing directly (above). `lookup` (and so
    /// the definitions) must outlive the plan: the general parts use it when rendering.
    static std::shared_ptr<const Plan> compile(const robdef::TypeDefinition& type, const robdef::TypeLookup& lookup,
                                               std::string_view context_service, const Limits& limits = {});

    /// Appends the JSON text of `element` to `out` and returns true; returns false with `out`
    /// unchanged when the element does not match the type (above). Never throws but std::bad_alloc.
    /// `omit_null_members`: a struct field or map entry whose value is null (an absent struct, list,
    /// map or varvalue) is left out of its object, as the recorder's json channels want it; nulls in
    /// arrays stay, and so does any null inside a part the general path writes (a caller that must
    /// have none looks for "null" in the text).
    bool append(std::string& out, const MessageElement& element, bool omit_null_members = false) const;

    struct Graph;  // the compiled nodes (element_json_plan.cpp)
    explicit Plan(std::unique_ptr<Graph> graph);
    ~Plan();

private:
    std::unique_ptr<Graph> graph_;
};

/// Appends `s` (valid UTF-8) as a JSON string, escaped as nlohmann's dump escapes it.
void append_string(std::string& out, std::string_view s);

}  // namespace rr::element_json_text
