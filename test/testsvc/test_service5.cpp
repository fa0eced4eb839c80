// TestService5.asynctestroot: RobotRaconteurTestService3. Every member answers asynchronously: the
// handler returns at once and the reply is completed later from the io_context, as a service whose
// answers wait for a device would.
#include <boost/asio/post.hpp>

#include "test/testsvc/test_services.hpp"

namespace rr::testsvc {

using namespace rr::server;

namespace {

/// Completes `done` with `r` later, from the io_context.
void later(boost::asio::io_context& io, Completion done, Result<Value> r) {
    boost::asio::post(io, [done = std::move(done), r = std::move(r)]() mutable { done(std::move(r)); });
}

/// f4: the doubles 0…15, each answered from the io_context.
class AsyncCount : public Generator {
public:
    explicit AsyncCount(boost::asio::io_context& io) : io_(io) {}
    void async_next(std::optional<Value>, Completion done) override {
        if (i_ >= 16) return later(io_, std::move(done), fail(MessageErrorType::StopIteration, ""));
        later(io_, std::move(done), Value::scalar<double>(i_++));
    }
    Result<void> close() override {
        i_ = 16;
        return {};
    }

private:
    boost::asio::io_context& io_;
    int i_ = 0;
};

/// f5(a, b): takes doubles until closed (void return).
class AsyncSink : public Generator {
public:
    explicit AsyncSink(boost::asio::io_context& io) : io_(io) {}
    void async_next(std::optional<Value> p, Completion done) override {
        if (closed_) return later(io_, std::move(done), fail(MessageErrorType::StopIteration, ""));
        if (!p || !p->as<double>()) return later(io_, std::move(done), fail(MessageErrorType::InvalidArgument, "double expected"));
        later(io_, std::move(done), Value());
    }
    Result<void> close() override {
        closed_ = true;
        return {};
    }

private:
    boost::asio::io_context& io_;
    bool closed_ = false;
};

/// f6(a, b): for each teststruct5 {a: string} sent, a teststruct4 {a: a + the string's length}.
class AsyncMeasure : public Generator {
public:
    AsyncMeasure(boost::asio::io_context& io, double a) : io_(io), a_(a) {}
    void async_next(std::optional<Value> p, Completion done) override {
        if (closed_) return later(io_, std::move(done), fail(MessageErrorType::StopIteration, ""));
        const Value* field = p ? p->field("a") : nullptr;
        auto s = field ? field->as<std::string>() : Result<std::string>(fail(MessageErrorType::InvalidArgument, "teststruct5 expected"));
        if (!s) return later(io_, std::move(done), fail(MessageErrorType::InvalidArgument, "teststruct5 with a string expected"));
        Structure out;
        out.type_name = kTs5 + ".teststruct4";
        out.set("a", Value::scalar<double>(a_ + static_cast<double>(s->size())));
        later(io_, std::move(done), Value(std::move(out)));
    }
    Result<void> close() override {
        closed_ = true;
        return {};
    }

private:
    boost::asio::io_context& io_;
    double a_;
    bool closed_ = false;
};

}  // namespace

std::shared_ptr<ServiceObject> make_async_test_root(const Context& c) {
    auto root = make_object(c, kTs5 + ".asynctestroot");
    auto* io = c.io;
    serve_table_properties(c, *root, {"d1", "err"}, true);

    must(root->set_async_property_handlers(
             "d1", [io](const SessionRef&, Completion done) { later(*io, std::move(done), Value::scalar<double>(8.5515)); },
             [io](const SessionRef&, Value v, SetCompletion done) {
                 auto d = v.as<double>();
                 Result<void> r;
                 if (!d || *d != 3.0819) r = fail(MessageErrorType::InvalidArgument, "d1: only 3.0819 may be set");
                 boost::asio::post(*io, [done = std::move(done), r = std::move(r)] { done(r); });
             }),
         "d1");
    must(root->set_async_property_handlers(
             "err",
             [io](const SessionRef&, Completion done) {
                 later(*io, std::move(done), fail(MessageErrorType::InvalidArgument, "Test message 1"));
             },
             [io](const SessionRef&, Value, SetCompletion done) {
                 boost::asio::post(*io, [done = std::move(done)] { done(fail(MessageErrorType::InvalidOperation, "Test message 2")); });
             }),
         "err");

    auto fn = [&](const char* name, AsyncFunctionHandler h) { must(root->set_async_function(name, std::move(h)), name); };
    fn("f1", [io](const SessionRef&, std::vector<Value>, Completion done) { later(*io, std::move(done), Value()); });
    fn("f2", [io](const SessionRef&, std::vector<Value> a, Completion done) {
        auto v = a[0].as<std::int32_t>();
        if (!v || *v != 247) return later(*io, std::move(done), fail(MessageErrorType::InvalidArgument, "f2: a must be 247"));
        later(*io, std::move(done), Value());
    });
    fn("f3", [io](const SessionRef&, std::vector<Value> a, Completion done) {
        auto x = a[0].as<double>();
        auto y = a[1].as<double>();
        if (!x || !y) return later(*io, std::move(done), fail(MessageErrorType::InvalidArgument, "f3: doubles expected"));
        const double sum = *x + *y;
        if (!(sum >= -2147483648.0 && sum <= 2147483647.0))
            return later(*io, std::move(done), fail(MessageErrorType::OutOfRange, "f3: a + b does not fit an int32"));
        later(*io, std::move(done), Value::scalar<std::int32_t>(static_cast<std::int32_t>(sum)));
    });
    fn("err_func", [io](const SessionRef&, std::vector<Value>, Completion done) {
        later(*io, std::move(done), fail(MessageErrorType::InvalidOperation, "err_func always fails"));
    });
    ServiceObject* self = root.get();
    fn("err_func2", [io, self](const SessionRef&, std::vector<Value>, Completion done) {
        later(*io, std::move(done), fail(self->user_error("asynctestexp", "err_func2 always fails")));
    });

    auto gen = [&](const char* name, GeneratorFunctionHandler h) { must(root->set_generator_function(name, std::move(h)), name); };
    gen("f4", [io](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
        return std::shared_ptr<Generator>(std::make_shared<AsyncCount>(*io));
    });
    gen("f5", [io](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
        return std::shared_ptr<Generator>(std::make_shared<AsyncSink>(*io));
    });
    gen("f6", [io](const SessionRef&, std::vector<Value> a) -> Result<std::shared_ptr<Generator>> {
        auto x = a[0].as<double>();
        if (!x) return x.take_error();
        return std::shared_ptr<Generator>(std::make_shared<AsyncMeasure>(*io, *x));
    });
    gen("err_func3", [](const SessionRef&, std::vector<Value>) -> Result<std::shared_ptr<Generator>> {
        return fail(MessageErrorType::InvalidOperation, "err_func3 always fails");
    });
    return root;
}

}  // namespace rr::testsvc
