#include <catch2/catch.hpp>

#include "base/error/rr_error.hpp"

using namespace rr;

TEST_CASE("error names map to codes and back") {
    CHECK(error_name(MessageErrorType::MemberNotFound) == "RobotRaconteur.MemberNotFound");
    CHECK(error_type_from_name("RobotRaconteur.ObjectLockedError") == MessageErrorType::ObjectLockedError);
    CHECK(error_type_from_name("RobotRaconteur.ServiceNotFoundException") == MessageErrorType::ServiceNotFound);
    CHECK(error_type_from_name("experimental.arm.MotorFault") == MessageErrorType::RemoteError);
    CHECK(error_name(MessageErrorType::RemoteError).empty());
}

TEST_CASE("Result carries a value or an error") {
    auto half = [](int x) -> Result<int> {
        if (x % 2) return fail(MessageErrorType::InvalidArgument, "odd");
        return x / 2;
    };
    auto ok = half(4);
    REQUIRE(ok);
    CHECK(*ok == 2);
    auto bad = half(3);
    REQUIRE_FALSE(bad);
    CHECK(bad.error().type == MessageErrorType::InvalidArgument);
    CHECK(bad.error().name == "RobotRaconteur.InvalidArgument");
    CHECK(bad.error().message == "odd");
}

TEST_CASE("a Result keeps its error boxed: small on success, errors copied and propagated whole") {
    // The decoder returns a Result per field: a success must not carry an RRError's three strings.
    CHECK(sizeof(Result<std::uint8_t>) <= 2 * sizeof(void*));
    CHECK(sizeof(Result<void>) <= 2 * sizeof(void*));

    Result<void> ok;
    CHECK(ok);
    Result<void> bad = fail(MessageErrorType::ObjectLockedError, std::string(100, 'x'));
    REQUIRE_FALSE(bad);
    Result<void> copy = bad;  // a deep copy: each owns its error
    auto forwarded = [&]() -> Result<std::string> { return bad.take_error(); }();
    REQUIRE_FALSE(forwarded);
    CHECK(forwarded.error().type == MessageErrorType::ObjectLockedError);
    CHECK(forwarded.error().name == "RobotRaconteur.ObjectLockedError");
    CHECK(forwarded.error().message == std::string(100, 'x'));
    REQUIRE_FALSE(copy);
    CHECK(copy.error().message == std::string(100, 'x'));

    Result<std::string> value = std::string("v");
    value = forwarded;  // assigning an error over a value, then a value over an error
    REQUIRE_FALSE(value);
    CHECK(value.error().type == MessageErrorType::ObjectLockedError);
    value = std::string("again");
    REQUIRE(value);
    CHECK(*value == "again");
    RRError moved = std::move(forwarded).error();
    CHECK(moved.message.size() == 100);
}
