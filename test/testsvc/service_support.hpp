// What the test services of rr-test-service share: setup failures end the program (a test service
// that starts half-built would answer wrongly later), table-driven properties, timers, zero contents.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>

#include "server/service/service_object.hpp"
#include "test/testsvc/test_values.hpp"

namespace rr::testsvc {

inline const std::string kTs1 = "com.robotraconteur.testing.TestService1";
inline const std::string kTs2 = "com.robotraconteur.testing.TestService2";
inline const std::string kTs3 = "com.robotraconteur.testing.TestService3";
inline const std::string kTs5 = "com.robotraconteur.testing.TestService5";

/// Ends the program with `what` and the error when setup fails.
[[noreturn]] void setup_failed(const std::string& what, const RRError& e);
template <class T>
T must(Result<T> r, const std::string& what) {
    if (!r) setup_failed(what, r.error());
    return std::move(*r);
}
inline void must(Result<void> r, const std::string& what) {
    if (!r) setup_failed(what, r.error());
}

/// What every test service object is built with.
struct Context {
    std::shared_ptr<const server::ServiceTypes> types;
    std::shared_ptr<const TestValues> values;
    boost::asio::io_context* io = nullptr;
};

/// A new object of `type` (qualified). Setup failure ends the program.
std::shared_ptr<server::ServiceObject> make_object(const Context& c, const std::string& type);

/// Serves every property of `obj` that is not in `except` from the values (test_values.hpp): gets
/// return values.get(), sets must equal values.expected_set() (InvalidArgument otherwise) and change
/// nothing. `async`: through the asynchronous handlers, answered from the io_context.
void serve_table_properties(const Context& c, server::ServiceObject& obj, const std::vector<std::string>& except = {},
                            bool async = false);

/// Checks a value a client sent against the expected one: InvalidArgument naming `what` when they differ.
Result<void> expect_value(const Value& got, const Value& expected, const std::string& what);

/// Runs `f` on the io_context after `delay` (once).
void after(boost::asio::io_context& io, std::chrono::milliseconds delay, std::function<void()> f);

/// `count` zero items of the scalar pod or namedarray type `type` (qualified), with `dims` for a
/// multi-dim memory (empty: 1-D); numeric arrays with no `type` name: `numeric` zeros.
Value zero_pods(const Context& c, const std::string& type, std::size_t count, std::vector<std::uint32_t> dims = {});
Value zero_namedarrays(const Context& c, const std::string& type, std::size_t count,
                       std::vector<std::uint32_t> dims = {});
Value zero_numbers(DataTypes type, std::size_t count, std::vector<std::uint32_t> dims = {});

}  // namespace rr::testsvc
