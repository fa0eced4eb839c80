#include "test/testsvc/service_support.hpp"

#include <algorithm>
#include <cstdlib>
#include <iostream>

#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>

#include "core/value/named_type.hpp"
#include "test/testsvc/value_fill.hpp"

namespace rr::testsvc {

void setup_failed(const std::string& what, const RRError& e) {
    std::cerr << "rr-test-service: " << what << ": " << e.name << ": " << e.message << std::endl;
    std::exit(2);
}

std::shared_ptr<server::ServiceObject> make_object(const Context& c, const std::string& type) {
    return must(server::ServiceObject::create(c.types, type), "object " + type);
}

Result<void> expect_value(const Value& got, const Value& expected, const std::string& what) {
    if (same_value(got, expected)) return {};
    return fail(MessageErrorType::InvalidArgument, what + ": not the value the test expects");
}

void serve_table_properties(const Context& c, server::ServiceObject& obj, const std::vector<std::string>& except,
                            bool async) {
    const std::string type = obj.type();
    for (const auto& m : obj.definition().members) {
        if (m.kind != robdef::MemberKind::property) continue;
        if (std::find(except.begin(), except.end(), m.name) != except.end()) continue;
        // Computed once: every get returns the same value.
        auto get = std::make_shared<const Value>(must(c.values->get(type, m.name), type + "." + m.name));
        auto set = std::make_shared<const std::optional<Value>>(must(c.values->expected_set(type, m.name), type + "." + m.name));
        const std::string what = "property " + m.name;
        auto check = [set, what](const Value& v) -> Result<void> {
            if (!set->has_value()) return {};
            return expect_value(v, **set, what);
        };
        if (!async) {
            must(obj.set_property_handlers(
                     m.name, [get](const server::SessionRef&) -> Result<Value> { return *get; },
                     [check](const server::SessionRef&, Value v) -> Result<void> { return check(v); }),
                 what);
            continue;
        }
        auto* io = c.io;
        must(obj.set_async_property_handlers(
                 m.name,
                 [get, io](const server::SessionRef&, server::Completion done) {
                     boost::asio::post(*io, [get, done = std::move(done)] { done(*get); });
                 },
                 [check, io](const server::SessionRef&, Value v, server::SetCompletion done) {
                     boost::asio::post(*io, [check, v = std::move(v), done = std::move(done)] { done(check(v)); });
                 }),
             what);
    }
}

void after(boost::asio::io_context& io, std::chrono::milliseconds delay, std::function<void()> f) {
    auto timer = std::make_shared<boost::asio::steady_timer>(io, delay);
    timer->async_wait([timer, f = std::move(f)](const boost::system::error_code& ec) {
        if (!ec) f();
    });
}

Value zero_numbers(DataTypes type, std::size_t count, std::vector<std::uint32_t> dims) {
    NumericArray a = NumericArray::zeros(type, count);
    if (!dims.empty()) return Value(MultiDimArray{std::move(dims), std::move(a)});
    return Value(std::move(a));
}

Value zero_pods(const Context& c, const std::string& type, std::size_t count, std::vector<std::uint32_t> dims) {
    // An LFSR stuck at zero draws all-zero numbers and empty variable-length arrays.
    Lfsr zero = Lfsr::from_state(0);
    robdef::TypeDefinition t;
    t.base = DataTypes::namedtype_t;
    t.type_name = type;
    Value one = must(lfsr_value(t, zero, c.types->set(), {}), "zero " + type);
    const auto& item = *one.get_if<PodArray>();
    PodArray p(item.type_name, item.field_names);
    for (std::size_t i = 0; i < count; ++i) must(p.push_back(item.values), "zero " + type);
    p.dims = std::move(dims);
    return Value(std::move(p));
}

Value zero_namedarrays(const Context& c, const std::string& type, std::size_t count, std::vector<std::uint32_t> dims) {
    auto nt = must(resolve_named_type(type, c.types->set(), {}), type);
    auto layout = must(namedarray_layout(nt, c.types->set()), type);
    return Value(NamedArray{nt.qualified_name, NumericArray::zeros(layout.element_type, count * layout.elements_per_item),
                            std::move(dims)});
}

}  // namespace rr::testsvc
