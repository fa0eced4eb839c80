#include "core/value/element_layout.hpp"

#include <charconv>
#include <cstring>

namespace rr {

using robdef::ArrayKind;
using robdef::ContainerKind;
using robdef::NamedTypeKind;
using robdef::TypeDefinition;

MessageElement void_element() { return MessageElement{}; }

MessageElement string_element(const std::string& s) {
    MessageElement e;
    e.type = DataTypes::string_t;
    e.data = SharedBytes::copy_of(s.data(), s.size());
    return e;
}

MessageElement array_element(std::string name, const NumericArray& a) {
    MessageElement e;
    e.name = std::move(name);
    e.type = a.type();
    e.data = a.to_bytes();
    return e;
}

MessageElement multidim_element(const std::vector<std::uint32_t>& dims, MessageElement array) {
    MessageElement e;
    e.type = DataTypes::multidimarray_t;
    e.elements.reserve(2);
    e.elements.push_back(array_element("dims", NumericArray::from<std::uint32_t>(dims)));
    array.name = "array";
    array.number.reset();
    e.elements.push_back(std::move(array));
    return e;
}

Result<void> check_count(std::size_t n, const TypeDefinition& t) {
    if (t.array == ArrayKind::none) {
        if (n != 1)
            return fail(MessageErrorType::DataTypeError,
                        "expected a scalar (1 item), got " + std::to_string(n) + " items");
        return {};
    }
    ArrayLengthRule rule = array_length_rule(t);
    if (rule.length == 0) return {};
    if (rule.exact && n != rule.length)
        return fail(MessageErrorType::DataTypeError, "expected " + std::to_string(rule.length) +
                                                         " items (" + t.to_string() + "), got " + std::to_string(n));
    if (!rule.exact && n > rule.length)
        return fail(MessageErrorType::DataTypeError, "expected at most " + std::to_string(rule.length) +
                                                         " items (" + t.to_string() + "), got " + std::to_string(n));
    return {};
}

namespace {
std::string dims_text(const std::vector<std::uint32_t>& dims) {
    std::string s = "[";
    for (std::size_t i = 0; i < dims.size(); ++i) s += (i ? "," : "") + std::to_string(dims[i]);
    return s + "]";
}
}  // namespace

Result<void> check_dims(const std::vector<std::uint32_t>& dims, std::size_t count, const TypeDefinition& t) {
    if (dims.empty()) return fail(MessageErrorType::DataTypeError, "multi-dim array needs at least one dim");
    std::size_t product = 0;
    if (!dims_product(dims, product) || product != count)
        return fail(MessageErrorType::DataTypeError, "multi-dim dims " + dims_text(dims) + " do not match " +
                                                         std::to_string(count) + " items");
    auto fixed = fixed_dims(t);
    if (!fixed.empty() && fixed != dims)
        return fail(MessageErrorType::DataTypeError,
                    "expected dims " + dims_text(fixed) + " (" + t.to_string() + "), got " + dims_text(dims));
    return {};
}

std::optional<std::int32_t> element_number(const MessageElement& e) noexcept {
    if (e.number) return *e.number;
    const std::string& n = e.name;
    if (n.empty()) return std::nullopt;
    std::int32_t v = 0;
    auto [p, ec] = std::from_chars(n.data(), n.data() + n.size(), v);
    if (ec != std::errc() || p != n.data() + n.size()) return std::nullopt;
    return v;
}

Result<std::vector<PodFieldPlan>> pod_field_plans(const NamedType& pod, const robdef::TypeLookup& lookup) {
    std::vector<PodFieldPlan> plans;
    plans.reserve(pod.entry->members.size());
    for (const auto& m : pod.entry->members) {
        if (m.kind != robdef::MemberKind::field) continue;
        auto bad = [&](std::string_view why) {
            return fail(MessageErrorType::DataTypeError,
                        "invalid pod \"" + pod.qualified_name + "\" field \"" + m.name + "\": " + std::string(why));
        };
        const TypeDefinition& ft = m.type;
        PodFieldPlan plan;
        plan.member = &m;
        if (ft.container != ContainerKind::none) return bad("containers are not allowed");
        if (ft.base == DataTypes::namedtype_t) {
            auto nt = resolve_named_type(ft, lookup, pod.service->name);
            if (!nt) return nt.take_error();
            if (nt->kind != NamedTypeKind::pod && nt->kind != NamedTypeKind::namedarray)
                return bad("only numeric, pod and namedarray fields allowed");
            plan.named = std::move(*nt);
        } else if (!is_numeric(ft.base)) {
            return bad("only numeric, pod and namedarray fields allowed");
        }
        if (ft.array == ArrayKind::multidimarray) {
            plan.dims = fixed_dims(ft);
            if (plan.dims.empty()) return bad("multi-dim fields need fixed dims");
            std::size_t n = 0;
            if (!dims_product(plan.dims, n, 0x7fffffff) || n == 0) return bad("bad dims");
            plan.multidim = true;
        }
        plan.wire_type = pod_field_wire_type(ft);
        if (plan.named.kind != NamedTypeKind::unresolved) plan.wire_type.qualified_name = plan.named.qualified_name;
        plans.push_back(std::move(plan));
    }
    return plans;
}

}  // namespace rr
