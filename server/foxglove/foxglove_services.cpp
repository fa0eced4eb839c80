// Functions as Foxglove services: serviceCallRequest → the JSON API's call → serviceCallResponse, or
// serviceCallFailure naming why.
#include "server/foxglove/foxglove_connection.hpp"

#include "server/gateway/json_push.hpp"

namespace rr::server::foxglove {

void FoxgloveConnection::on(fg::event::ServiceCall e) {
    auto server = server_.lock();
    auto member = server ? server->service_member(e.service_id) : nullptr;
    const std::uint32_t service = e.service_id, call = e.call_id;
    auto self = shared_from_this();
    auto failed = [self, service, call](const std::string& why) {
        std::lock_guard lock(self->mutex_);
        self->session_.call_finished(service, call);
        if (!self->closed_) self->socket_->send(fg::service_call_failure_json(service, call, why));
    };
    if (!member) return failed("service " + std::to_string(service) + " is gone");
    nlohmann::json args = nullptr;
    if (!e.payload.empty()) {
        args = nlohmann::json::parse(e.payload, nullptr, false);
        if (args.is_discarded() || !(args.is_object() || args.is_array() || args.is_null()))
            return failed("the request is not a JSON object of the arguments by name (or an array of them in order)");
    }
    api_->call_function(address_of(*member), args, 0, [self, service, call, failed, encoding = e.encoding](gateway::ApiResult r) {
        if (!r) return failed(error_text(*r.error));
        std::string frame = fg::service_call_response_head(service, call, encoding) + gateway::json_text(r.value);
        std::lock_guard lock(self->mutex_);
        self->session_.call_finished(service, call);
        if (!self->closed_) self->socket_->send_binary(std::move(frame));
    });
}
}  // namespace rr::server::foxglove
