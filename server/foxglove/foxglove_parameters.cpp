// Properties as Foxglove parameters: getParameters, setParameters (then read back, and sent to every
// subscribed client), subscribeParameterUpdates, under the login's rights (the JSON API checks them).
#include "server/foxglove/foxglove_connection.hpp"


namespace rr::server::foxglove {

bool FoxgloveConnection::begin_parameter_request() {
    std::lock_guard lock(mutex_);
    if (parameter_requests_ >= options_.max_parameter_requests) {
        status("parameter request refused: more than " + std::to_string(options_.max_parameter_requests) +
               " getParameters / setParameters being answered on this connection");
        return false;
    }
    ++parameter_requests_;
    return true;
}

// Reads `members` and hands the values (in order; failures left out and named in one status) to `done`.
void FoxgloveConnection::read_parameters(std::vector<std::shared_ptr<const LiveMember>> members,
                     std::function<void(std::vector<fg::Parameter>)> done) {
    struct Gather {
        std::mutex m;
        std::vector<std::optional<fg::Parameter>> values;
        std::vector<std::string> failures;
        std::size_t left = 0;
    };
    auto g = std::make_shared<Gather>();
    g->values.resize(members.size());
    g->left = members.size();
    if (members.empty()) return done({});
    auto self = shared_from_this();
    for (std::size_t i = 0; i < members.size(); ++i) {
        const std::string name = members[i]->topic;
        api_->get_property(address_of(*members[i]), [self, g, i, name, done](gateway::ApiResult r) {
            bool last = false;
            {
                std::lock_guard lock(g->m);
                if (r)
                    g->values[i] = fg::Parameter{name, r.value.value("value", nlohmann::json()), ""};
                else
                    g->failures.push_back(name + ": " + error_text(*r.error));
                last = --g->left == 0;
            }
            if (!last) return;
            std::vector<fg::Parameter> out;
            for (auto& v : g->values)
                if (v) out.push_back(std::move(*v));
            if (!g->failures.empty()) {
                std::string text = "parameters not read: ";
                for (std::size_t k = 0; k < g->failures.size(); ++k) text += (k ? "; " : "") + g->failures[k];
                std::lock_guard lock(self->mutex_);
                if (!self->closed_) self->status(text, fg::StatusLevel::warning);
            }
            done(std::move(out));
        });
    }
}

// The properties `names` name ("" → all); unknown names in `unknown`.
std::vector<std::shared_ptr<const LiveMember>> FoxgloveConnection::properties_named(const std::vector<std::string>& names,
                                                                std::vector<std::string>& unknown) const {
    auto server = server_.lock();
    if (!server) return {};
    if (names.empty()) return server->properties();
    std::vector<std::shared_ptr<const LiveMember>> out;
    for (const auto& n : names) {
        if (auto m = server->member_named(n, LiveKind::property))
            out.push_back(std::move(m));
        else
            unknown.push_back(n);
    }
    return out;
}

void FoxgloveConnection::report_unknown(const std::vector<std::string>& unknown, const char* op) {
    if (unknown.empty()) return;
    std::string text = std::string(op) + ": no property named ";
    for (std::size_t i = 0; i < unknown.size(); ++i) text += (i ? ", \"" : "\"") + unknown[i] + "\"";
    std::lock_guard lock(mutex_);
    status(text, fg::StatusLevel::warning);
}

void FoxgloveConnection::on(fg::event::GetParameters e) {
    if (!begin_parameter_request()) return;
    std::vector<std::string> unknown;
    auto members = properties_named(e.names, unknown);
    report_unknown(unknown, "getParameters");
    auto self = shared_from_this();
    read_parameters(std::move(members), [self, id = e.id](std::vector<fg::Parameter> values) {
        std::lock_guard lock(self->mutex_);
        --self->parameter_requests_;
        if (!self->closed_) self->socket_->send(fg::parameter_values_json(values, id));
    });
}

void FoxgloveConnection::on(fg::event::SetParameters e) {
    if (!begin_parameter_request()) return;
    struct Gather {
        std::mutex m;
        std::vector<std::shared_ptr<const LiveMember>> set;
        std::vector<std::string> failures;
        std::size_t left = 0;
    };
    auto g = std::make_shared<Gather>();
    auto server = server_.lock();
    std::vector<std::pair<std::shared_ptr<const LiveMember>, nlohmann::json>> writes;
    for (auto& p : e.parameters) {
        auto m = server ? server->member_named(p.name, LiveKind::property) : nullptr;
        if (!m) {
            g->failures.push_back(p.name + ": no such property");
        } else if (p.type == "byte_array") {
            g->failures.push_back(p.name + ": byte_array values are not taken (send the JSON mapping's array)");
        } else if (p.value.is_null()) {
            g->failures.push_back(p.name + ": a property cannot be unset");
        } else {
            writes.emplace_back(std::move(m), std::move(p.value));
        }
    }
    g->left = writes.size();
    auto self = shared_from_this();
    auto finish = [self, g, id = e.id] {
        if (!g->failures.empty()) {
            std::string text = "setParameters: not set: ";
            for (std::size_t k = 0; k < g->failures.size(); ++k) text += (k ? "; " : "") + g->failures[k];
            std::lock_guard lock(self->mutex_);
            if (!self->closed_) self->status(text);
        }
        // The values now: the reply (with the request's id) and the update to every subscriber.
        self->read_parameters(g->set, [self, id](std::vector<fg::Parameter> values) {
            {
                std::lock_guard lock(self->mutex_);
                --self->parameter_requests_;
                if (id && !self->closed_) self->socket_->send(fg::parameter_values_json(values, id));
            }
            if (auto server = self->server_.lock())
                for (const auto& v : values) server->parameter_changed(v);
        });
    };
    if (writes.empty()) return finish();
    for (auto& [m, value] : writes) {
        std::shared_ptr<const LiveMember> member = m;
        api_->set_property(address_of(*member), value, [g, member, finish](gateway::ApiResult r) {
            bool last = false;
            {
                std::lock_guard lock(g->m);
                if (r)
                    g->set.push_back(member);
                else
                    g->failures.push_back(member->topic + ": " + error_text(*r.error));
                last = --g->left == 0;
            }
            if (last) finish();
        });
    }
}

void FoxgloveConnection::on(fg::event::ParametersSubscribed e) {
    if (!begin_parameter_request()) return;
    std::vector<std::string> unknown;
    auto members = properties_named(e.all ? std::vector<std::string>{} : e.names, unknown);
    report_unknown(unknown, "subscribeParameterUpdates");
    auto self = shared_from_this();
    read_parameters(std::move(members), [self](std::vector<fg::Parameter> values) {
        std::lock_guard lock(self->mutex_);
        --self->parameter_requests_;
        if (!self->closed_ && !values.empty()) self->socket_->send(fg::parameter_values_json(values, std::nullopt));
    });
}
}  // namespace rr::server::foxglove
