#include <catch2/catch.hpp>

#include "core/error/rr_error.hpp"

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
