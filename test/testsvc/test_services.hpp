// The four official test services, on the project's service API (server/service):
//
//   RobotRaconteurTestService       com.robotraconteur.testing.TestService1.testroot   (TestRoot)
//   RobotRaconteurTestService_auth  the same type behind password logins                (TestRoot)
//   RobotRaconteurTestService2      com.robotraconteur.testing.TestService3.testroot3  (TestRoot3)
//   RobotRaconteurTestService3      com.robotraconteur.testing.TestService5.asynctestroot (AsyncTestRoot)
//
// The behaviour of each member is what the official clients expect (robotraconteur/robotraconteur,
// test/python and test/cpp/service); members the official services leave unimplemented get a
// behaviour of ours. docs/native-service.md lists both, member by member.
#pragma once

#include <memory>

#include "server/service/object_service.hpp"
#include "test/testsvc/service_support.hpp"

namespace rr::testsvc {

class TestRoot {
public:
    /// `attributes`: the service attributes of RobotRaconteurTestService ("test", "test2").
    static std::shared_ptr<TestRoot> create(const Context& c);
    ~TestRoot();
    const std::shared_ptr<server::ServiceObject>& root() const;
    /// Called once the service serves the root (for o6_op's path releases).
    void attach(const std::shared_ptr<server::ObjectService>& service);
    /// The broadcast pipe and wire (every 25 ms while clients are connected to them).
    void tick();

    struct State;

private:
    explicit TestRoot(std::unique_ptr<State> state);
    std::unique_ptr<State> s_;
};

class TestRoot3 {
public:
    static std::shared_ptr<TestRoot3> create(const Context& c);
    ~TestRoot3();
    const std::shared_ptr<server::ServiceObject>& root() const;
    /// Locks `nolock_test` for the user "server", as the official test service does.
    void attach(const std::shared_ptr<server::ObjectService>& service);

    struct State;

private:
    explicit TestRoot3(std::unique_ptr<State> state);
    std::unique_ptr<State> s_;
};

/// TestService5.asynctestroot: every handler answers asynchronously (from the io_context).
std::shared_ptr<server::ServiceObject> make_async_test_root(const Context& c);

}  // namespace rr::testsvc
