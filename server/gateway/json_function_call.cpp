// JsonApi::call_function: FunctionCallReq with parameters by name, and generator functions collected
// into a list (wire.md §6.7: GeneratorNextReq with `index` [+ `parameter`] until StopIteration; close =
// a GeneratorNextReq carrying Error StopIteration).
#include "base/message/error_entry.hpp"
#include "core/session/elements.hpp"
#include "server/gateway/json_api.hpp"

namespace rr::server::gateway {

namespace {

robdef::TypeDefinition item_type(robdef::TypeDefinition t) {
    t.container = robdef::ContainerKind::none;
    return t;
}

// Runs a generator to its end, to max_items, or until the parameter items are used up; then closes it.
class GeneratorRun : public std::enable_shared_from_this<GeneratorRun> {
public:
    GeneratorRun(std::shared_ptr<const JsonApi> api, MemberTarget t, std::int32_t index,
                 std::vector<MessageElement> parameters, bool has_parameter, std::size_t max_items, JsonApi::Done done)
        : api_(std::move(api)), t_(std::move(t)), index_(index), parameters_(std::move(parameters)),
          has_parameter_(has_parameter), max_items_(max_items), done_(std::move(done)),
          returns_(t_.member->type.container == robdef::ContainerKind::generator),
          return_type_(item_type(t_.member->type)) {}

    void step() {
        if ((has_parameter_ && next_ >= parameters_.size()) || (returns_ && items_.size() >= max_items_)) {
            close(std::nullopt);
            return;
        }
        MessageEntry e;
        e.entry_type = MessageEntryType::GeneratorNextReq;
        e.service_path = t_.path;
        e.member_name = t_.member->name;
        e.elements.push_back(make_scalar_element<std::int32_t>("index", index_));
        if (has_parameter_) e.elements.push_back(std::move(parameters_[next_++]));
        auto self = shared_from_this();
        t_.device->request(std::move(e), [self](Result<MessageEntry> r) {
            if (!r) return self->finish(device_error(r.error()));
            if (auto err = entry_error(*r)) {
                // StopIteration is the generator's normal end; any other error ends it as well.
                if (err->type == MessageErrorType::StopIteration) return self->finish(std::nullopt);
                return self->finish(device_error(*err));
            }
            if (self->returns_) {
                const auto* ret = r->find("return");
                if (!ret)
                    return self->close(api_error(502, MessageErrorType::MessageElementNotFound,
                                                 "GeneratorNextRes from the device has no \"return\" element"));
                auto j = self->api_->element_json(*ret, self->return_type_, self->t_);
                if (!j) return self->close(*j.error);
                self->items_.push_back(std::move(j.value));
            }
            self->step();
        }, t_.device_session);
    }

private:
    void close(std::optional<ApiError> error) {
        MessageEntry e;
        e.entry_type = MessageEntryType::GeneratorNextReq;
        e.service_path = t_.path;
        e.member_name = t_.member->name;
        set_entry_error(e, make_error(MessageErrorType::StopIteration, ""));
        e.elements.push_back(make_scalar_element<std::int32_t>("index", index_));
        auto self = shared_from_this();
        t_.device->request(std::move(e), [self, error = std::move(error)](Result<MessageEntry> r) {
            // A device may answer a close with StopIteration: the generator is closed either way.
            if (!error && !r) return self->finish(device_error(r.error()));
            if (!error && r) {
                if (auto err = entry_error(*r); err && err->type != MessageErrorType::StopIteration)
                    return self->finish(device_error(*err));
            }
            self->finish(error);
        }, t_.device_session);
    }

    void finish(std::optional<ApiError> error) {
        if (error) {
            done_(ApiResult::failed(std::move(*error)));
            return;
        }
        done_(ApiResult::ok(nlohmann::json{{"items", std::move(items_)}}));
    }

    std::shared_ptr<const JsonApi> api_;
    MemberTarget t_;
    std::int32_t index_;
    std::vector<MessageElement> parameters_;
    std::size_t next_ = 0;
    bool has_parameter_;
    std::size_t max_items_;
    JsonApi::Done done_;
    bool returns_;
    robdef::TypeDefinition return_type_;
    nlohmann::json items_ = nlohmann::json::array();
};

}  // namespace

void JsonApi::call_function(const MemberAddress& address, const nlohmann::json& args, std::size_t max_items, Done done) {
    if (auto denied = check_access(address, auth::Operation::call)) return done(ApiResult::failed(std::move(*denied)));
    if (max_items == 0) max_items = options_.default_max_items;
    if (max_items > options_.max_items_limit) {
        done(ApiResult::failed(api_error(400, MessageErrorType::InvalidArgument,
                                         "max_items is above " + std::to_string(options_.max_items_limit))));
        return;
    }
    auto self = shared_from_this();
    resolve(address, [self, address, args, max_items, done = std::move(done)](Resolved r) mutable {
        if (auto* e = std::get_if<ApiError>(&r)) return done(ApiResult::failed(*e));
        const auto& t = std::get<MemberTarget>(r);
        const auto& m = *t.member;
        if (m.kind != robdef::MemberKind::function)
            return done(ApiResult::failed(api_error(404, MessageErrorType::MemberNotFound,
                                                    "member \"" + m.name + "\" of " + t.object_type + " is " +
                                                        robdef::with_article(robdef::member_kind_keyword(m.kind)) +
                                                        ", not a function")));
        const bool param_generator =
            !m.parameters.empty() && m.parameters.back().container == robdef::ContainerKind::generator;
        const bool generator = param_generator || m.type.container == robdef::ContainerKind::generator;

        // Arguments: positional array, object by name, or nothing.
        auto bad = [&](std::string message) {
            done(ApiResult::failed(api_error(400, MessageErrorType::InvalidArgument, std::move(message))));
        };
        std::vector<const nlohmann::json*> given(m.parameters.size(), nullptr);
        if (args.is_array()) {
            if (args.size() != m.parameters.size())
                return bad("function \"" + m.name + "\" takes " + std::to_string(m.parameters.size()) +
                           " argument(s), got " + std::to_string(args.size()));
            for (std::size_t i = 0; i < given.size(); ++i) given[i] = &args[i];
        } else if (args.is_object()) {
            for (auto it = args.begin(); it != args.end(); ++it) {
                const std::string& key = it.key();
                std::size_t i = 0;
                while (i < m.parameters.size() && m.parameters[i].name != key) ++i;
                if (i == m.parameters.size())
                    return bad("function \"" + m.name + "\" has no parameter \"" + key + "\"");
                given[i] = &*it;
            }
            for (std::size_t i = 0; i < given.size(); ++i)
                if (!given[i]) return bad("missing argument \"" + m.parameters[i].name + "\"");
        } else if (!args.is_null() || !m.parameters.empty()) {
            return bad("args must be an array or an object of the parameters of \"" + m.name + "\"");
        }

        MessageEntry call;
        call.entry_type = MessageEntryType::FunctionCallReq;
        call.service_path = t.path;
        call.member_name = m.name;
        std::vector<MessageElement> gen_items;
        for (std::size_t i = 0; i < m.parameters.size(); ++i) {
            const auto& p = m.parameters[i];
            ApiError error;
            if (param_generator && i + 1 == m.parameters.size()) {
                const auto& items = *given[i];
                if (!items.is_array()) return bad("argument \"" + p.name + "\" (" + p.to_string() + ") must be an array of items");
                const auto type = item_type(p);
                for (std::size_t k = 0; k < items.size(); ++k) {
                    auto el = self->element_from_json(items[k], type, t, "parameter", error,
                                                      "argument \"" + p.name + "\"[" + std::to_string(k) + "]");
                    if (!el) return done(ApiResult::failed(error));
                    gen_items.push_back(std::move(*el));
                }
                continue;
            }
            auto el = self->element_from_json(*given[i], p, t, p.name, error, "argument \"" + p.name + "\"");
            if (!el) return done(ApiResult::failed(error));
            call.elements.push_back(std::move(*el));
        }

        // Motion safety: a hold-to-run timeout clamped, another client's motion refused, a stop through
        // every lock (docs/security.md "Motion safety").
        auto admitted = admit_motion(address, t, call);
        if (auto* refused = std::get_if<ApiError>(&admitted)) return done(ApiResult::failed(std::move(*refused)));
        auto motion = std::make_shared<MotionAdmission>(std::get<MotionAdmission>(std::move(admitted)));
        // A generator is checked once, at its call: its items are one JSON API request.
        if (!motion->stop)
            if (auto locked = self->check_locks(t, MessageEntryType::FunctionCallReq)) {
                finish_motion(*motion, fail(MessageErrorType::ObjectLockedError, locked->message));
                return done(ApiResult::failed(std::move(*locked)));
            }
        if (motion->ticket && motion->ticket->kind == MotionGuard::Ticket::Kind::generator) {
            // The generator's motion ends with the run (its end, max_items reached, an error).
            done = [motion, inner = std::move(done)](ApiResult result) {
                MotionGuard::Ticket end{MotionGuard::Ticket::Kind::generator_next};
                end.generator = motion->generator_index;
                end.closes = true;
                if (motion->guard) motion->guard->on_reply(motion->client, end, MessageEntry{});
                inner(std::move(result));
            };
        }
        auto send = [&](auto&& on_reply) {
            if (motion->stop) return t.device->request_stop(std::move(call), std::move(on_reply), t.device_session);
            t.device->request(std::move(call), std::move(on_reply), t.device_session);
        };
        send([self, t, generator, param_generator, max_items, done, motion,
              gen_items = std::move(gen_items)](Result<MessageEntry> r) mutable {
            finish_motion(*motion, r);
            if (r && r->error == MessageErrorType::None)
                if (const auto* idx = r->find("index")) (void)read_scalar(*idx, motion->generator_index);
            if (!r) return done(ApiResult::failed(device_error(r.error())));
            if (auto err = entry_error(*r)) return done(ApiResult::failed(device_error(*err)));
            if (!generator) {
                if (t.member->type.is_void()) return done(ApiResult::ok(nlohmann::json{{"return", nullptr}}));
                const auto* ret = r->find("return");
                if (!ret)
                    return done(ApiResult::failed(api_error(502, MessageErrorType::MessageElementNotFound,
                                                            "FunctionCallRes from the device has no \"return\" element")));
                auto j = self->element_json(*ret, t.member->type, t);
                if (!j) return done(j);
                return done(ApiResult::ok(nlohmann::json{{"return", std::move(j.value)}}));
            }
            std::int32_t index = -1;
            const auto* idx = r->find("index");
            if (!idx || !read_scalar(*idx, index))
                return done(ApiResult::failed(api_error(502, MessageErrorType::MessageElementNotFound,
                                                        "FunctionCallRes of a generator has no \"index\" element")));
            auto run = std::make_shared<GeneratorRun>(self, t, index, std::move(gen_items), param_generator, max_items, done);
            run->step();
        });
    });
}

}  // namespace rr::server::gateway
