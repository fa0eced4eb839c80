#include "server/service/callback_member.hpp"

#include "base/message/error_entry.hpp"
#include "server/service/member_support.hpp"

namespace rr::server {

const std::string& CallbackMember::name() const noexcept { return info_->def->name; }

void CallbackMember::call(const SessionRef& session, std::vector<Value> args, Completion done) const {
    const auto& def = *info_->def;
    if (args.size() != def.parameters.size()) {
        done(fail(MessageErrorType::DataTypeError, "callback " + def.name + " takes " +
                                                       std::to_string(def.parameters.size()) + " arguments, got " +
                                                       std::to_string(args.size())));
        return;
    }
    auto owner = info_->owner.lock();
    std::vector<std::string> paths;
    if (owner) paths = owner->paths();
    if (paths.empty()) {
        done(fail(MessageErrorType::InvalidOperation, "callback " + def.name + ": the object is not served"));
        return;
    }
    MessageEntry entry = detail::member_entry(MessageEntryType::CallbackCallReq, paths.front(), def.name);
    entry.elements.reserve(args.size());
    for (std::size_t i = 0; i < args.size(); ++i) {
        auto e = detail::pack_member(*info_, args[i], def.parameters[i], def.parameters[i].name);
        if (!e) {
            done(e.take_error());
            return;
        }
        entry.elements.push_back(std::move(*e));
    }
    session.request(std::move(entry), [info = info_, done = std::move(done)](Result<MessageEntry> reply) {
        if (!reply) {
            done(reply.take_error());
            return;
        }
        if (auto err = entry_error(*reply)) {
            done(fail(std::move(*err)));
            return;
        }
        if (info->def->type.is_void()) {
            done(Value());
            return;
        }
        auto e = detail::require_element(*reply, "return");
        if (!e) {
            done(e.take_error());
            return;
        }
        done(detail::unpack_member(*info, **e, info->def->type));
    });
}

}  // namespace rr::server
