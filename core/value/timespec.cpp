#include "core/value/timespec.hpp"

#include "core/value/element_layout.hpp"

namespace rr {

namespace {

Result<TimeSpec> checked(std::int64_t s, std::int32_t ns) {
    if (ns < 0 || ns >= 1'000'000'000)
        return fail(MessageErrorType::DataTypeError, "TimeSpec nanoseconds " + std::to_string(ns) + " out of [0, 1e9)");
    return TimeSpec{s, ns};
}

template <class T>
Result<T> scalar_field(const MessageElement& e, std::string_view name) {
    const MessageElement* c = e.find(name);
    if (!c) return fail(MessageErrorType::MessageElementNotFound, "TimeSpec field " + std::string(name) + " missing");
    if (c->type != numeric_type_v<T>)
        return fail(MessageErrorType::DataTypeMismatch, "TimeSpec field " + std::string(name) + " has the wrong type");
    auto a = NumericArray::wrap(c->type, c->data);
    if (!a) return a.take_error();
    if (a->size() != 1)
        return fail(MessageErrorType::DataTypeError, "TimeSpec field " + std::string(name) + " must be a scalar");
    return a->template at<T>(0);
}

template <class T>
Result<T> scalar_value(const Structure& s, std::string_view name) {
    const Value* v = s.find(name);
    if (!v) return fail(MessageErrorType::MessageElementNotFound, "TimeSpec field " + std::string(name) + " missing");
    auto* a = v->get_if<NumericArray>();
    if (!a || a->type() != numeric_type_v<T>)
        return fail(MessageErrorType::DataTypeMismatch, "TimeSpec field " + std::string(name) + " has the wrong type");
    if (a->size() != 1)
        return fail(MessageErrorType::DataTypeError, "TimeSpec field " + std::string(name) + " must be a scalar");
    return a->template at<T>(0);
}

}  // namespace

MessageElement pack_timespec(const TimeSpec& t, std::string_view element_name) {
    MessageElement e;
    e.name = std::string(element_name);
    e.type = DataTypes::structure_t;
    e.type_name = std::string(kTimeSpecTypeName);
    e.elements.reserve(2);
    e.elements.push_back(array_element("seconds", NumericArray::scalar(t.seconds)));
    e.elements.push_back(array_element("nanoseconds", NumericArray::scalar(t.nanoseconds)));
    return e;
}

Result<TimeSpec> unpack_timespec(const MessageElement& e) {
    if (e.type == DataTypes::void_t) return fail(MessageErrorType::NullValue, "TimeSpec must not be null");
    if (e.type != DataTypes::structure_t || e.type_name != kTimeSpecTypeName)
        return fail(MessageErrorType::DataTypeMismatch, "expected a RobotRaconteur.TimeSpec struct");
    auto s = scalar_field<std::int64_t>(e, "seconds");
    if (!s) return s.take_error();
    auto ns = scalar_field<std::int32_t>(e, "nanoseconds");
    if (!ns) return ns.take_error();
    return checked(*s, *ns);
}

Value timespec_to_value(const TimeSpec& t) {
    Structure s{std::string(kTimeSpecTypeName), {}};
    s.fields.push_back(Field{"seconds", Value::scalar(t.seconds)});
    s.fields.push_back(Field{"nanoseconds", Value::scalar(t.nanoseconds)});
    return Value(std::move(s));
}

Result<TimeSpec> timespec_from_value(const Value& v) {
    if (v.is_null()) return fail(MessageErrorType::NullValue, "TimeSpec must not be null");
    auto* s = v.get_if<Structure>();
    if (!s || s->type_name != kTimeSpecTypeName)
        return fail(MessageErrorType::DataTypeMismatch, "expected a RobotRaconteur.TimeSpec struct");
    auto sec = scalar_value<std::int64_t>(*s, "seconds");
    if (!sec) return sec.take_error();
    auto ns = scalar_value<std::int32_t>(*s, "nanoseconds");
    if (!ns) return ns.take_error();
    return checked(*sec, *ns);
}

}  // namespace rr
