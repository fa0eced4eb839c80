// NativeClient (native_client.hpp): ClientContext operations with their values converted to/from JS.
#include "wasm-client/src/native_client.hpp"

#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <string>

#include "core/value/var_type.hpp"
#include "robdef/canonical_text.hpp"
#include "wasm-client/src/js_results.hpp"
#include "wasm-client/src/js_values.hpp"

namespace rr::wasm {
namespace {

using emscripten::val;
using robdef::MemberKind;

MonoTime mono(double ms) {
    return MonoTime(std::chrono::duration_cast<MonoTime::duration>(std::chrono::duration<double, std::milli>(ms)));
}

double mono_ms(MonoTime t) { return std::chrono::duration<double, std::milli>(t.time_since_epoch()).count(); }

TimeSpec wall(double ms) {
    double s = std::floor(ms / 1000.0);
    return TimeSpec{static_cast<std::int64_t>(s), static_cast<std::int32_t>((ms - s * 1000.0) * 1e6)};
}

template <class T>
val result_to_js(const Result<T>& r) {
    return r ? ok() : err(r.error());
}

val timespec_to_js(const TimeSpec& t) {
    val o = val::object();
    o.set("seconds", static_cast<double>(t.seconds));
    o.set("nanoseconds", t.nanoseconds);
    return o;
}

val wire_value_to_js(val value, const WireValue& w) {
    val o = val::object();
    o.set("value", value);
    o.set("ts", timespec_to_js(w.timestamp));
    return o;
}

std::string service_of(std::string_view qualified) {
    auto dot = qualified.rfind('.');
    return dot == std::string_view::npos ? std::string() : std::string(qualified.substr(0, dot));
}

std::string_view kind_name(MemberKind k) { return robdef::member_kind_keyword(k); }

}  // namespace

NativeClient::NativeClient(val config) : ctx_(make_config(config), mono(config["now"].as<double>())) {
    ctx_.set_connect_handler([this](Result<ObjectRef> r) {
        if (on_connected_.isUndefined()) return;
        if (!r) return (void)on_connected_(error_to_js(r.error()), val::null());
        on_connected_(val::null(), object_to_js(*r));
    });
    ctx_.set_closed_handler([this](const RRError& e) {
        if (!on_closed_.isUndefined()) on_closed_(error_to_js(e));
    });
    ctx_.set_path_released_handler([this](const std::string& path) {
        if (!on_released_.isUndefined()) on_released_(u8(path));
    });
}

void NativeClient::set_handlers(val connected, val closed, val released) {
    on_connected_ = connected;
    on_closed_ = closed;
    on_released_ = released;
}

val NativeClient::feed(val bytes, double now) {
    std::size_t n = bytes["length"].as<std::size_t>();
    in_.resize(n);
    if (n) val(emscripten::typed_memory_view(n, reinterpret_cast<std::uint8_t*>(in_.data()))).call<void>("set", bytes);
    return result_to_js(ctx_.feed(in_, mono(now)));
}

val NativeClient::take_output() {
    if (ctx_.pending_output_size() == 0) return val::null();
    ctx_.take_output(out_);
    val view(emscripten::typed_memory_view(out_.size(), reinterpret_cast<const std::uint8_t*>(out_.data())));
    return view.call<val>("slice");
}

double NativeClient::next_deadline() const {
    auto d = ctx_.next_deadline();
    return d ? mono_ms(*d) : -1.0;
}

void NativeClient::transport_closed(std::string message) {
    ctx_.on_transport_closed(make_error(MessageErrorType::ConnectionError, std::move(message)));
}

val NativeClient::info() const {
    val o = val::object();
    const auto& neg = ctx_.session().stream().negotiated();
    o.set("nodeName", u8(neg.remote_node_name));
    o.set("nodeId", neg.remote_node_id.to_string());
    o.set("root", object_to_js(ctx_.root()));
    val defs = val::object();
    for (const auto* d : ctx_.definitions().definitions()) {
        if (d->name == "RobotRaconteurServiceIndex") continue;  // built in, never pulled
        defs.set(u8(d->name), u8(robdef::to_string(*d)));
    }
    // The texts as received, where we have them (canonical text only for definitions pulled later).
    for (const auto& text : ctx_.info().service_definitions) {
        robdef::ServiceDefinitionSet one;
        auto parsed = one.add_text(text, "received");
        if (!parsed) continue;
        for (const auto* d : one.definitions())
            if (d->name != "RobotRaconteurServiceIndex") defs.set(u8(d->name), u8(text));
    }
    o.set("definitions", defs);
    return o;
}

val NativeClient::describe(std::string path) const {
    auto obj = ctx_.object(path);
    if (!obj) return err(make_error(MessageErrorType::ObjectNotFound, "no object at " + path));
    auto t = ctx_.definitions().find(obj->type);
    if (!t || !t.entry) return err(make_error(MessageErrorType::ServiceDefinitionError, "no definition of " + obj->type));
    val o = object_to_js(*obj);
    val members = val::array();
    std::size_t i = 0;
    for (const auto& m : t.entry->members) {
        val d = val::object();
        d.set("name", m.name);
        d.set("kind", std::string(kind_name(m.kind)));
        d.set("type", m.kind == MemberKind::event ? std::string("void") : m.type.to_string());
        val params = val::array();
        for (std::size_t j = 0; j < m.parameters.size(); ++j) {
            val p = val::object();
            p.set("name", m.parameters[j].name);
            p.set("type", m.parameters[j].to_string());
            params.set(j, p);
        }
        d.set("params", params);
        d.set("generator", m.kind == MemberKind::function && m.is_generator());
        d.set("readonly", m.direction() == robdef::MemberDirection::readonly);
        d.set("writeonly", m.direction() == robdef::MemberDirection::writeonly);
        if (m.kind == MemberKind::objref) {
            const auto index = robdef::objref_index_kind(m.type);
            d.set("index", index == robdef::ObjRefIndexKind::int32    ? val(std::string("int32"))
                           : index == robdef::ObjRefIndexKind::string ? val(std::string("string"))
                                                                      : val::null());
        }
        if (m.kind == MemberKind::memory)
            d.set("multidim", m.type.array == robdef::ArrayKind::multidimarray);
        members.set(i++, d);
    }
    o.set("members", members);
    return ok(o);
}

void NativeClient::property_get(std::string path, std::string member, double now, val cb) {
    auto t = typed(path, member);
    if (!t) return (void)cb(error_to_js(t.error()), val::null());
    ctx_.property_get(path, member, mono(now), [this, t = *t, cb](Result<Value> r) {
        deliver(cb, r, t.member->type, t.ctx);
    });
}

void NativeClient::property_set(std::string path, std::string member, val value, double now, val cb) {
    auto t = typed(path, member);
    if (!t) return (void)cb(error_to_js(t.error()), val::null());
    auto v = from_js(value, t->member->type, ctx_.definitions(), t->ctx);
    if (!v) return (void)cb(error_to_js(v.error()), val::null());
    ctx_.property_set(path, member, std::move(*v), mono(now), void_completion(cb));
}

void NativeClient::call(std::string path, std::string member, val args, double now, val cb) {
    auto t = typed(path, member);
    if (!t) return (void)cb(error_to_js(t.error()), val::null());
    auto a = args_from_js(*t, args, t->member->parameters.size());
    if (!a) return (void)cb(error_to_js(a.error()), val::null());
    ctx_.call(path, member, std::move(*a), mono(now), [this, t = *t, cb](Result<Value> r) {
        deliver(cb, r, t.member->type, t.ctx);
    });
}

void NativeClient::call_generator(std::string path, std::string member, val args, double now, val cb) {
    auto t = typed(path, member);
    if (!t) return (void)cb(error_to_js(t.error()), val::null());
    const auto& params = t->member->parameters;
    bool param_gen = !params.empty() && params.back().container == robdef::ContainerKind::generator;
    auto a = args_from_js(*t, args, params.size() - (param_gen ? 1 : 0));
    if (!a) return (void)cb(error_to_js(a.error()), val::null());
    GeneratorTypes g;
    g.ctx = t->ctx;
    g.return_type = without_generator(t->member->type);
    if (param_gen) g.param_type = without_generator(params.back());
    ctx_.call_generator(path, member, std::move(*a), mono(now),
                        [this, g = std::move(g), cb](Result<GeneratorHandle> r) mutable {
                            if (!r) return (void)cb(error_to_js(r.error()), val::null());
                            generators_[r->id] = std::move(g);
                            cb(val::null(), static_cast<double>(r->id));
                        });
}

void NativeClient::generator_next(double id, val param, double now, val cb) {
    auto it = generators_.find(static_cast<std::uint64_t>(id));
    if (it == generators_.end())
        return (void)cb(error_to_js(make_error(MessageErrorType::InvalidOperation, "generator closed")), val::null());
    const GeneratorTypes& g = it->second;
    std::optional<Value> p;
    if (g.param_type) {
        auto v = from_js(param, *g.param_type, ctx_.definitions(), g.ctx);
        if (!v) return (void)cb(error_to_js(v.error()), val::null());
        p = std::move(*v);
    }
    ctx_.generator_next(GeneratorHandle{it->first}, std::move(p), mono(now),
                        [this, rt = g.return_type, c = g.ctx, cb](Result<Value> r) { deliver(cb, r, rt, c); });
}

void NativeClient::generator_close(double id, bool abort, double now, val cb) {
    auto h = GeneratorHandle{static_cast<std::uint64_t>(id)};
    generators_.erase(h.id);
    if (abort) ctx_.generator_abort(h, mono(now), void_completion(cb));
    else ctx_.generator_close(h, mono(now), void_completion(cb));
}

void NativeClient::objref(std::string path, std::string member, val index, double now, val cb) {
    ObjRefIndex i;
    auto jt = index.typeOf().as<std::string>();
    if (jt == "number") i = index.as<std::int32_t>();
    else if (jt == "string") i = index.as<std::string>();
    ctx_.objref(path, member, std::move(i), mono(now), [this, cb](Result<ObjectRef> r) {
        if (!r) return (void)cb(error_to_js(r.error()), val::null());
        cb(val::null(), object_to_js(*r));
    });
}

val NativeClient::subscribe_event(std::string path, std::string member, val handler) {
    auto t = typed(path, member);
    if (!t) return err(t.error());
    auto id = ctx_.subscribe_event(path, member, [this, t = *t, handler](const std::string&, std::vector<Value>& args) {
        auto js = values_to_js(args, t.member->parameters, t.ctx);
        if (!js) return;  // a value that cannot be shown is dropped (the service sent it typed)
        handler(*js);
    });
    if (!id) return err(id.error());
    return ok(val(static_cast<double>(*id)));
}

val NativeClient::set_callback(std::string path, std::string member, val handler) {
    auto t = typed(path, member);
    if (!t) return err(t.error());
    if (handler.isNull() || handler.isUndefined()) return result_to_js(ctx_.set_deferred_callback(path, member, nullptr));
    return result_to_js(ctx_.set_deferred_callback(
        path, member, [this, t = *t, handler](std::vector<Value>& args, Completion<Value> reply) {
            auto js = values_to_js(args, t.member->parameters, t.ctx);
            if (!js) return reply(js.take_error());
            double id = static_cast<double>(++next_reply_);
            replies_[next_reply_] = PendingReply{std::move(reply), t};
            handler(*js, id);
        }));
}

void NativeClient::callback_reply(double id, val error, val value) {
    auto it = replies_.find(static_cast<std::uint64_t>(id));
    if (it == replies_.end()) return;
    PendingReply p = std::move(it->second);
    replies_.erase(it);
    if (!error.isNull() && !error.isUndefined()) {
        RRError e;
        e.name = error["name"].typeOf().as<std::string>() == "string" ? error["name"].as<std::string>() : "";
        e.message = error["message"].typeOf().as<std::string>() == "string" ? error["message"].as<std::string>() : "";
        e.type = e.name.empty() ? MessageErrorType::RemoteError : error_type_from_name(e.name);
        if (e.name.empty()) e.name = "RobotRaconteur.UnknownError";
        return p.reply(fail(std::move(e)));
    }
    if (p.typed.member->type.is_void()) return p.reply(Value());
    auto v = from_js(value, p.typed.member->type, ctx_.definitions(), p.typed.ctx);
    if (!v) return p.reply(v.take_error());
    p.reply(std::move(*v));
}

void NativeClient::pipe_connect(std::string path, std::string member, int index, double now, val cb) {
    auto t = typed(path, member);
    if (!t) return (void)cb(error_to_js(t.error()), val::null());
    ctx_.pipe_connect(path, member, index, mono(now), [this, t = *t, cb](Result<PipeEndpointHandle> r) {
        if (!r) return (void)cb(error_to_js(r.error()), val::null());
        pipe_types_[r->id] = t;
        auto info = ctx_.pipe_info(*r);
        val o = val::object();
        o.set("id", static_cast<double>(r->id));
        o.set("index", info ? info->index : 0);
        cb(val::null(), o);
    });
}

val NativeClient::pipe_set_handlers(double id, val packets, val ack, val closed) {
    PipeEndpointHandlers h;
    h.packets = [packets](PipeEndpointHandle) { packets(); };
    h.ack = [ack](PipeEndpointHandle, std::uint32_t n) { ack(n); };
    h.closed = [closed](PipeEndpointHandle, const RRError& e) { closed(error_to_js(e)); };
    return result_to_js(ctx_.set_pipe_handlers(PipeEndpointHandle{static_cast<std::uint64_t>(id)}, std::move(h)));
}

val NativeClient::pipe_send(double id, val value, double now) {
    PipeEndpointHandle h{static_cast<std::uint64_t>(id)};
    auto t = pipe_types_.find(h.id);
    if (t == pipe_types_.end()) return err(make_error(MessageErrorType::InvalidOperation, "pipe endpoint closed"));
    auto v = from_js(value, t->second.member->type, ctx_.definitions(), t->second.ctx);
    if (!v) return err(v.error());
    auto n = ctx_.pipe_send(h, *v, mono(now));
    if (!n) return err(n.error());
    return ok(val(*n));
}

val NativeClient::pipe_receive(double id) {
    PipeEndpointHandle h{static_cast<std::uint64_t>(id)};
    auto t = pipe_types_.find(h.id);
    if (t == pipe_types_.end()) return ok();
    auto v = ctx_.pipe_receive(h);
    if (!v) return ok();
    auto js = to_js(*v, t->second.member->type, ctx_.definitions(), t->second.ctx);
    if (!js) return err(js.error());
    val o = val::object();
    o.set("packet", *js);
    return ok(o);
}

void NativeClient::pipe_close(double id, double now, val cb) {
    PipeEndpointHandle h{static_cast<std::uint64_t>(id)};
    pipe_types_.erase(h.id);
    ctx_.pipe_close(h, mono(now), void_completion(cb));
}

void NativeClient::wire_connect(std::string path, std::string member, double now, val cb) {
    auto t = typed(path, member);
    if (!t) return (void)cb(error_to_js(t.error()), val::null());
    ctx_.wire_connect(path, member, mono(now), [this, t = *t, cb](Result<WireConnectionHandle> r) {
        if (!r) return (void)cb(error_to_js(r.error()), val::null());
        wire_types_[r->id] = t;
        cb(val::null(), static_cast<double>(r->id));
    });
}

val NativeClient::wire_set_handlers(double id, val value, val closed) {
    WireConnectionHandle h{static_cast<std::uint64_t>(id)};
    auto t = wire_types_.find(h.id);
    if (t == wire_types_.end()) return err(make_error(MessageErrorType::InvalidOperation, "wire connection closed"));
    WireConnectionHandlers hs;
    hs.value = [this, t = t->second, value](WireConnectionHandle, const WireValue& w) {
        auto js = to_js(w.value, t.member->type, ctx_.definitions(), t.ctx);
        if (js) value(wire_value_to_js(*js, w));
    };
    hs.closed = [closed](WireConnectionHandle, const RRError& e) { closed(error_to_js(e)); };
    return result_to_js(ctx_.set_wire_handlers(h, std::move(hs)));
}

val NativeClient::wire_set_out_value(double id, val value, double wall_ms, double now) {
    WireConnectionHandle h{static_cast<std::uint64_t>(id)};
    auto t = wire_types_.find(h.id);
    if (t == wire_types_.end()) return err(make_error(MessageErrorType::InvalidOperation, "wire connection closed"));
    auto v = from_js(value, t->second.member->type, ctx_.definitions(), t->second.ctx);
    if (!v) return err(v.error());
    return result_to_js(ctx_.wire_set_out_value(h, std::move(*v), wall(wall_ms), mono(now)));
}

val NativeClient::wire_set_lifespans(double id, int in_ms, int out_ms) {
    return result_to_js(ctx_.set_wire_lifespans(WireConnectionHandle{static_cast<std::uint64_t>(id)}, in_ms, out_ms));
}

void NativeClient::wire_close(double id, double now, val cb) {
    WireConnectionHandle h{static_cast<std::uint64_t>(id)};
    wire_types_.erase(h.id);
    ctx_.wire_close(h, mono(now), void_completion(cb));
}

void NativeClient::wire_peek(std::string path, std::string member, bool in, double now, val cb) {
    auto t = typed(path, member);
    if (!t) return (void)cb(error_to_js(t.error()), val::null());
    auto done = [this, t = *t, cb](Result<WireValue> r) {
        if (!r) return (void)cb(error_to_js(r.error()), val::null());
        auto js = to_js(r->value, t.member->type, ctx_.definitions(), t.ctx);
        if (!js) return (void)cb(error_to_js(js.error()), val::null());
        cb(val::null(), wire_value_to_js(*js, *r));
    };
    if (in) ctx_.wire_peek_in_value(path, member, mono(now), std::move(done));
    else ctx_.wire_peek_out_value(path, member, mono(now), std::move(done));
}

void NativeClient::wire_poke(std::string path, std::string member, val value, double wall_ms, double now, val cb) {
    auto t = typed(path, member);
    if (!t) return (void)cb(error_to_js(t.error()), val::null());
    auto v = from_js(value, t->member->type, ctx_.definitions(), t->ctx);
    if (!v) return (void)cb(error_to_js(v.error()), val::null());
    ctx_.wire_poke_out_value(path, member, std::move(*v), wall(wall_ms), mono(now), void_completion(cb));
}

void NativeClient::memory_param(std::string path, std::string member, std::string what, double now, val cb) {
    auto number = [cb](Result<std::uint64_t> r) {
        if (!r) return (void)cb(error_to_js(r.error()), val::null());
        cb(val::null(), static_cast<double>(*r));
    };
    if (what == "length") return ctx_.memory_length(path, member, mono(now), number);
    if (what == "dimcount") return ctx_.memory_dim_count(path, member, mono(now), number);
    ctx_.memory_dimensions(path, member, mono(now), [cb](Result<std::vector<std::uint64_t>> r) {
        if (!r) return (void)cb(error_to_js(r.error()), val::null());
        val a = val::array();
        for (std::size_t i = 0; i < r->size(); ++i) a.set(i, static_cast<double>((*r)[i]));
        cb(val::null(), a);
    });
}

void NativeClient::memory_read(std::string path, std::string member, val start, val count, double now, val cb) {
    auto t = typed(path, member);
    if (!t) return (void)cb(error_to_js(t.error()), val::null());
    auto done = [this, t = *t, cb](Result<Value> r) { deliver(cb, r, t.member->type, t.ctx); };
    if (t->member->type.array == robdef::ArrayKind::multidimarray) {
        auto p = u64_list(start), c = u64_list(count);
        if (!p || !c) return (void)cb(error_to_js(make_error(MessageErrorType::InvalidArgument, "start and count must be arrays of non-negative integers")), val::null());
        return ctx_.memory_read(path, member, std::move(*p), std::move(*c), mono(now), std::move(done));
    }
    auto p = u64(start), c = u64(count);
    if (!p || !c) return (void)cb(error_to_js(make_error(MessageErrorType::InvalidArgument, "start and count must be non-negative integers")), val::null());
    ctx_.memory_read(path, member, *p, *c, mono(now), std::move(done));
}

void NativeClient::memory_write(std::string path, std::string member, val start, val data, double now, val cb) {
    auto t = typed(path, member);
    if (!t) return (void)cb(error_to_js(t.error()), val::null());
    auto v = from_js(data, t->member->type, ctx_.definitions(), t->ctx);
    if (!v) return (void)cb(error_to_js(v.error()), val::null());
    if (t->member->type.array == robdef::ArrayKind::multidimarray) {
        auto p = u64_list(start);
        if (!p) return (void)cb(error_to_js(make_error(MessageErrorType::InvalidArgument, "start must be an array of non-negative integers")), val::null());
        return ctx_.memory_write(path, member, std::move(*p), std::move(*v), mono(now), void_completion(cb));
    }
    auto p = u64(start);
    if (!p) return (void)cb(error_to_js(make_error(MessageErrorType::InvalidArgument, "start must be a non-negative integer")), val::null());
    ctx_.memory_write(path, member, *p, std::move(*v), mono(now), void_completion(cb));
}

ClientContextConfig NativeClient::make_config(const val& c) {
    ClientContextConfig cfg;
    auto str = [&](const char* k) { return c[k].typeOf().as<std::string>() == "string" ? c[k].as<std::string>() : std::string(); };
    cfg.session.service_name = str("service");
    cfg.session.username = str("username");
    cfg.session.password = str("password");
    cfg.session.stream.local_node_name = str("nodeName");
    cfg.session.stream.target_node_name = str("targetNodeName");
    if (auto id = NodeID::parse(str("targetNodeId")); id) cfg.session.stream.target_node_id = *id;
    NodeID::Bytes b{};
    val bytes = c["nodeId"];
    for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<std::byte>(bytes[i].as<int>());
    cfg.session.stream.local_node_id = NodeID(b);
    cfg.session.stream.enable_string_table = true;
    cfg.session.local_endpoint = c["endpoint"].as<std::uint32_t>();
    auto ms = [&](const char* k) -> std::optional<std::chrono::milliseconds> {
        if (c[k].typeOf().as<std::string>() != "number") return std::nullopt;
        return std::chrono::milliseconds(c[k].as<int>());
    };
    if (auto t = ms("requestTimeoutMs")) cfg.session.request_timeout = *t;
    // Liveness (wire.md §6.3): ConnectionTest after this long without sending, close after this long
    // without receiving. The JS layer validates them; the defaults are the official TCP client's.
    if (auto t = ms("heartbeatPeriodMs")) cfg.session.stream.heartbeat_period = *t;
    if (auto t = ms("receiveTimeoutMs")) cfg.session.stream.receive_timeout = *t;
    return cfg;
}

val NativeClient::object_to_js(const ObjectRef& r) const {
    val o = val::object();
    o.set("path", u8(r.path));
    o.set("type", u8(r.type));
    val impl = val::array();
    for (std::size_t i = 0; i < r.implements.size(); ++i) impl.set(i, r.implements[i]);
    o.set("implements", impl);
    return o;
}

Result<Typed> NativeClient::typed(const std::string& path, const std::string& member) const {
    auto m = ctx_.member_definition(path, member);
    if (!m) return m.take_error();
    auto obj = ctx_.object(path);
    return Typed{*m, obj ? service_of(obj->type) : std::string()};
}

robdef::TypeDefinition NativeClient::without_generator(robdef::TypeDefinition t) {
    if (t.container == robdef::ContainerKind::generator) t.container = robdef::ContainerKind::none;
    return t;
}

Result<std::vector<Value>> NativeClient::args_from_js(const Typed& t, const val& args, std::size_t n) const {
    std::size_t given = args["length"].as<std::size_t>();
    if (given != n)
        return fail(MessageErrorType::InvalidArgument, t.member->name + " takes " + std::to_string(n) +
                                                            " arguments, got " + std::to_string(given));
    std::vector<Value> out;
    for (std::size_t i = 0; i < n; ++i) {
        const auto& p = t.member->parameters[i];
        auto v = from_js(args[i], p, ctx_.definitions(), t.ctx);
        if (!v) return fail(v.error().type, "parameter " + p.name + ": " + v.error().message);
        out.push_back(std::move(*v));
    }
    return out;
}

void NativeClient::deliver(const val& cb, const Result<Value>& r, const robdef::TypeDefinition& type, const std::string& ctx) {
    if (!r) return (void)cb(error_to_js(r.error()), val::null());
    if (type.is_void()) return (void)cb(val::null(), val::undefined());
    auto js = to_js(*r, type, ctx_.definitions(), ctx);
    if (!js) return (void)cb(error_to_js(js.error()), val::null());
    cb(val::null(), *js);
}

Completion<void> NativeClient::void_completion(val cb) {
    return [cb](Result<void> r) {
        if (!r) return (void)cb(error_to_js(r.error()), val::null());
        cb(val::null(), val::undefined());
    };
}

val NativeClient::wire_value(double id, double now, bool in) {
    WireConnectionHandle h{static_cast<std::uint64_t>(id)};
    auto t = wire_types_.find(h.id);
    if (t == wire_types_.end()) return err(make_error(MessageErrorType::InvalidOperation, "wire connection closed"));
    auto w = in ? ctx_.wire_in_value(h, mono(now)) : ctx_.wire_out_value(h, mono(now));
    if (!w) return err(w.error());
    auto js = to_js(w->value, t->second.member->type, ctx_.definitions(), t->second.ctx);
    if (!js) return err(js.error());
    return ok(wire_value_to_js(*js, *w));
}

std::optional<std::uint64_t> NativeClient::u64(const val& v) {
    if (v.typeOf().as<std::string>() != "number") return std::nullopt;
    double d = v.as<double>();
    if (!(d >= 0) || std::trunc(d) != d || d > 9007199254740992.0) return std::nullopt;
    return static_cast<std::uint64_t>(d);
}

std::optional<std::vector<std::uint64_t>> NativeClient::u64_list(const val& v) {
    if (!val::global("Array").call<bool>("isArray", v)) return std::nullopt;
    std::vector<std::uint64_t> out;
    std::size_t n = v["length"].as<std::size_t>();
    for (std::size_t i = 0; i < n; ++i) {
        auto x = u64(v[i]);
        if (!x) return std::nullopt;
        out.push_back(*x);
    }
    return out;
}

Result<val> NativeClient::values_to_js(const std::vector<Value>& values,
                                       const std::vector<robdef::TypeDefinition>& types, const std::string& ctx) const {
    val a = val::array();
    for (std::size_t i = 0; i < values.size() && i < types.size(); ++i) {
        auto js = to_js(values[i], types[i], ctx_.definitions(), ctx);
        if (!js) return js.take_error();
        a.set(i, *js);
    }
    return a;
}

void NativeClient::monitor(std::string path, bool enter, int timeout_ms, double now, val cb) {
    if (enter) ctx_.monitor_enter(path, timeout_ms, mono(now), void_completion(cb));
    else ctx_.monitor_exit(path, mono(now), void_completion(cb));
}

void NativeClient::on_timer(double now) { ctx_.on_timer(mono(now)); }
void NativeClient::disconnect(double now) { ctx_.disconnect(mono(now)); }
bool NativeClient::is_connected() const { return ctx_.is_connected(); }
bool NativeClient::is_closed() const { return ctx_.is_closed(); }
void NativeClient::unsubscribe_event(double id) { ctx_.unsubscribe_event(static_cast<std::uint64_t>(id)); }
val NativeClient::wire_in_value(double id, double now) { return wire_value(id, now, true); }
val NativeClient::wire_out_value(double id, double now) { return wire_value(id, now, false); }

}  // namespace rr::wasm
