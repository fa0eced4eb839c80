// ClientContext: generator functions (wire.md §6.7): FunctionCallReq answered with `index`, then
// GeneratorNextReq with `index` [+ `parameter`]; the end is Error StopIteration; close = a request with
// Error StopIteration, abort = Error AbortOperation (CORE Generator.cpp).
#include "core/session/client_context.hpp"
#include "core/session/client_state.hpp"
#include "core/session/elements.hpp"
#include "core/value/named_type.hpp"

namespace rr {

using robdef::ContainerKind;
using robdef::MemberKind;

void ClientContext::call_generator(std::string_view path, std::string_view member, std::vector<Value> args,
                                   MonoTime now, Completion<GeneratorHandle> done) {
    const ObjectState* obj = nullptr;
    auto m = find_member(path, member, MemberKind::function, &obj);
    if (!m) return done(m.take_error());
    const robdef::MemberDefinition* def = *m;
    if (!def->is_generator())
        return done(fail(MessageErrorType::InvalidOperation,
                         "function \"" + std::string(member) + "\" is not a generator function: use call"));
    const bool param_gen = !def->parameters.empty() && def->parameters.back().container == ContainerKind::generator;
    const std::size_t n = def->parameters.size() - (param_gen ? 1 : 0);
    if (args.size() != n)
        return done(fail(MessageErrorType::InvalidArgument, "generator function \"" + std::string(member) +
                                                                "\" takes " + std::to_string(n) + " arguments, got " +
                                                                std::to_string(args.size())));
    const std::string& svc = obj->service->name;
    auto e = member_entry(MessageEntryType::FunctionCallReq, path, member);
    for (std::size_t i = 0; i < n; ++i) {
        auto el = pack(args[i], def->parameters[i], def->parameters[i].name, svc);
        if (!el) return done(el.take_error());
        e.elements.push_back(std::move(*el));
    }
    auto st = std::make_shared<GeneratorState>();  // shared: std::function needs a copyable capture
    st->path = std::string(path);
    st->member = std::string(member);
    st->context_service = svc;
    st->return_type = without_container(def->type);
    if (param_gen) st->parameter_type = without_container(def->parameters.back());
    send_request(std::move(e), now, [this, st = std::move(st), done = std::move(done)](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        if (!r) return done(r.take_error());
        const auto* idx = r->find("index");
        if (!idx || !read_scalar(*idx, st->index))
            return done(fail(MessageErrorType::MessageElementNotFound, "FunctionCallRes of a generator without index"));
        GeneratorHandle h{++next_id_};
        generators_.emplace(h.id, std::make_unique<GeneratorState>(std::move(*st)));
        done(h);
    });
}

void ClientContext::generator_next(GeneratorHandle g, std::optional<Value> parameter, MonoTime now,
                                   Completion<Value> done) {
    auto it = generators_.find(g.id);
    if (it == generators_.end())
        return done(fail(MessageErrorType::InvalidOperation, "generator closed or unknown"));
    GeneratorState& st = *it->second;
    if (st.parameter_type.has_value() != parameter.has_value())
        return done(fail(MessageErrorType::InvalidArgument, st.parameter_type ? "this generator's Next needs a parameter"
                                                                               : "this generator's Next takes no parameter"));
    auto e = member_entry(MessageEntryType::GeneratorNextReq, st.path, st.member);
    e.elements.push_back(make_scalar_element<std::int32_t>("index", st.index));
    if (parameter) {
        auto el = pack(*parameter, *st.parameter_type, "parameter", st.context_service);
        if (!el) return done(el.take_error());
        e.elements.push_back(std::move(*el));
    }
    send_request(std::move(e), now, [this, id = g.id, done = std::move(done)](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        auto it2 = generators_.find(id);
        if (!r) {
            // The service ends the generator with StopIteration (and after an abort): forget it.
            auto t = r.error().type;
            if (it2 != generators_.end() &&
                (t == MessageErrorType::StopIteration || t == MessageErrorType::OperationAborted ||
                 t == MessageErrorType::AbortOperation))
                generators_.erase(it2);
            return done(r.take_error());
        }
        if (it2 == generators_.end()) return done(fail(MessageErrorType::InvalidOperation, "generator closed"));
        const GeneratorState& st2 = *it2->second;
        if (st2.return_type.is_void()) return done(Value());
        const auto* v = r->find("return");
        if (!v) return done(fail(MessageErrorType::MessageElementNotFound, "GeneratorNextRes without return"));
        done(unpack(*v, st2.return_type, st2.context_service));
    });
}

namespace {

// The close / abort request of generator `g` (its state is forgotten at once: the handle is released).
Result<MessageEntry> generator_end_entry(
    std::map<std::uint64_t, std::unique_ptr<ClientContext::GeneratorState>>& gens, GeneratorHandle g,
    const RRError& how) {
    auto it = gens.find(g.id);
    if (it == gens.end()) return fail(MessageErrorType::InvalidOperation, "generator closed or unknown");
    auto e = member_entry(MessageEntryType::GeneratorNextReq, it->second->path, it->second->member);
    set_entry_error(e, how);
    e.elements.push_back(make_scalar_element<std::int32_t>("index", it->second->index));
    gens.erase(it);
    return e;
}

}  // namespace

void ClientContext::generator_close(GeneratorHandle g, MonoTime now, Completion<void> done) {
    auto e = generator_end_entry(generators_, g, make_error(MessageErrorType::StopIteration, ""));
    if (!e) return done(e.take_error());
    send_request(std::move(*e), now, [done = std::move(done)](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        // A service may answer a close with StopIteration itself: the generator is closed either way.
        if (!r && r.error().type != MessageErrorType::StopIteration) return done(r.take_error());
        done({});
    });
}

void ClientContext::generator_abort(GeneratorHandle g, MonoTime now, Completion<void> done) {
    auto e = generator_end_entry(generators_, g,
                                 make_error(MessageErrorType::AbortOperation, "Generator abort requested"));
    if (!e) return done(e.take_error());
    send_request(std::move(*e), now, [done = std::move(done)](Result<MessageEntry> r) {
        r = reply_result(std::move(r));
        if (!r && r.error().type != MessageErrorType::OperationAborted &&
            r.error().type != MessageErrorType::AbortOperation)
            return done(r.take_error());
        done({});
    });
}

}  // namespace rr
