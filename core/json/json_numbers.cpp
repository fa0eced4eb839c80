#include "core/json/json_numbers.hpp"

#include <charconv>
#include <cmath>
#include <limits>

namespace rr::json_numbers {

using nlohmann::json;

namespace {

json real_to_json(double d) {
    if (std::isnan(d)) return "NaN";
    if (std::isinf(d)) return d > 0 ? "Infinity" : "-Infinity";
    return d;
}

Result<double> real_from_json(const json& j) {
    if (j.is_number()) return j.get<double>();
    if (j.is_string()) {
        const auto& s = j.get_ref<const std::string&>();
        if (s == "NaN") return std::numeric_limits<double>::quiet_NaN();
        if (s == "Infinity") return std::numeric_limits<double>::infinity();
        if (s == "-Infinity") return -std::numeric_limits<double>::infinity();
    }
    return fail(MessageErrorType::DataTypeMismatch,
                "expected a number or \"NaN\"/\"Infinity\"/\"-Infinity\", got " + std::string(j.type_name()));
}

template <class R>
Result<R> real_as(const json& j) {
    auto d = real_from_json(j);
    if (!d) return d.take_error();
    if constexpr (std::is_same_v<R, float>) {
        if (std::isfinite(*d) && std::fabs(*d) > static_cast<double>(std::numeric_limits<float>::max()))
            return fail(MessageErrorType::OutOfRange, "number outside the single range");
    }
    return static_cast<R>(*d);
}

template <class T>
Result<T> integer_from_json(const json& j) {
    auto range = [](auto v) -> Result<T> {
        if (!std::in_range<T>(v))
            return fail(MessageErrorType::OutOfRange, "integer " + std::to_string(v) + " outside the " +
                                                          std::string(data_type_keyword(numeric_type_v<T>)) +
                                                          " range");
        return static_cast<T>(v);
    };
    if (j.is_number_unsigned()) return range(j.get<std::uint64_t>());
    if (j.is_number_integer()) return range(j.get<std::int64_t>());
    if (j.is_number_float()) {
        double d = j.get<double>();
        if (!std::isfinite(d) || std::trunc(d) != d || std::fabs(d) > static_cast<double>(kMaxExactInteger))
            return fail(MessageErrorType::OutOfRange, "number is not an exact integer");
        return range(static_cast<std::int64_t>(d));
    }
    if (j.is_string()) {
        const auto& s = j.get_ref<const std::string&>();
        const char* b = s.data();
        const char* e = s.data() + s.size();
        if (!s.empty() && s[0] == '-') {
            std::int64_t v = 0;
            auto [p, ec] = std::from_chars(b, e, v);
            if (ec == std::errc::result_out_of_range) return fail(MessageErrorType::OutOfRange, "integer \"" + s + "\" out of range");
            if (ec == std::errc() && p == e) return range(v);
        } else {
            std::uint64_t v = 0;
            auto [p, ec] = std::from_chars(b, e, v);
            if (ec == std::errc::result_out_of_range) return fail(MessageErrorType::OutOfRange, "integer \"" + s + "\" out of range");
            if (ec == std::errc() && p == e) return range(v);
        }
        return fail(MessageErrorType::DataTypeMismatch, "expected an integer, got the string \"" + s + "\"");
    }
    return fail(MessageErrorType::DataTypeMismatch, "expected an integer, got " + std::string(j.type_name()));
}

}  // namespace

template <Numeric T>
json to_json(T v) {
    if constexpr (std::is_same_v<T, bool>) {
        return v;
    } else if constexpr (detail::is_complex_v<T>) {
        return json{{"re", real_to_json(v.real())}, {"im", real_to_json(v.imag())}};
    } else if constexpr (std::is_floating_point_v<T>) {
        return real_to_json(static_cast<double>(v));
    } else if constexpr (sizeof(T) == 8) {
        bool exact = std::is_signed_v<T> ? (static_cast<std::int64_t>(v) >= -static_cast<std::int64_t>(kMaxExactInteger) &&
                                            static_cast<std::int64_t>(v) <= static_cast<std::int64_t>(kMaxExactInteger))
                                         : static_cast<std::uint64_t>(v) <= kMaxExactInteger;
        if (exact) return v;
        return std::to_string(v);
    } else {
        return v;
    }
}

template <Numeric T>
Result<T> from_json(const json& j) {
    if constexpr (std::is_same_v<T, bool>) {
        if (!j.is_boolean())
            return fail(MessageErrorType::DataTypeMismatch, "expected true or false, got " + std::string(j.type_name()));
        return j.get<bool>();
    } else if constexpr (detail::is_complex_v<T>) {
        using R = typename T::value_type;
        if (!j.is_object() || j.size() != 2 || !j.contains("re") || !j.contains("im"))
            return fail(MessageErrorType::DataTypeMismatch, "expected {\"re\":…,\"im\":…}, got " + j.dump());
        auto re = real_as<R>(j["re"]);
        if (!re) return re.take_error();
        auto im = real_as<R>(j["im"]);
        if (!im) return im.take_error();
        return T(*re, *im);
    } else if constexpr (std::is_floating_point_v<T>) {
        return real_as<T>(j);
    } else {
        return integer_from_json<T>(j);
    }
}

#define RR_JSON_NUMBER(T)                  \
    template json to_json<T>(T);           \
    template Result<T> from_json<T>(const json&);
RR_JSON_NUMBER(double)
RR_JSON_NUMBER(float)
RR_JSON_NUMBER(std::int8_t)
RR_JSON_NUMBER(std::uint8_t)
RR_JSON_NUMBER(std::int16_t)
RR_JSON_NUMBER(std::uint16_t)
RR_JSON_NUMBER(std::int32_t)
RR_JSON_NUMBER(std::uint32_t)
RR_JSON_NUMBER(std::int64_t)
RR_JSON_NUMBER(std::uint64_t)
RR_JSON_NUMBER(cdouble)
RR_JSON_NUMBER(csingle)
RR_JSON_NUMBER(bool)
#undef RR_JSON_NUMBER

json array_to_json(const NumericArray& a) {
    return dispatch_numeric(a.type(), [&](auto tag) {
        using T = typename decltype(tag)::type;
        json::array_t out;
        out.reserve(a.size());
        for (T v : a.view<T>()) out.push_back(to_json<T>(v));
        return json(std::move(out));
    });
}

json item_to_json(const NumericArray& a, std::size_t i) {
    return dispatch_numeric(a.type(), [&](auto tag) {
        using T = typename decltype(tag)::type;
        return to_json<T>(a.at<T>(i));
    });
}

Result<NumericArray> array_from_json(const json& j, DataTypes type, std::size_t* bad_index) {
    if (!j.is_array())
        return fail(MessageErrorType::DataTypeMismatch, "expected an array, got " + std::string(j.type_name()));
    NumericArray a = NumericArray::zeros(type, j.size());
    Result<void> ok = dispatch_numeric(type, [&](auto tag) -> Result<void> {
        using T = typename decltype(tag)::type;
        auto out = a.mutable_span<T>();
        for (std::size_t i = 0; i < out.size(); ++i) {
            auto v = from_json<T>(j[i]);
            if (!v) {
                if (bad_index) *bad_index = i;
                return v.take_error();
            }
            out[i] = *v;
        }
        return {};
    });
    if (!ok) return ok.take_error();
    return a;
}

}  // namespace rr::json_numbers
