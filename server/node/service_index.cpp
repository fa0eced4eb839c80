#include "server/node/service_index.hpp"

#include <algorithm>
#include <mutex>
#include <vector>

#include "core/session/elements.hpp"
#include "core/value/pack_value.hpp"
#include "robdef/builtin/service_index.hpp"
#include "robdef/service_definition_set.hpp"
#include "server/node/node.hpp"

namespace rr::server {

namespace {

std::string qualified(std::string_view name) {
    return std::string(robdef::kServiceIndexServiceName) + "." + std::string(name);
}

// CORE keeps only array-valued attributes (strings and numeric arrays) in ServiceInfo.
MapString index_attributes(const Service& service) {
    MapString out;
    auto all = unpack_value_untyped(service.attributes());
    const MapString* map = all ? all->get_if<MapString>() : nullptr;
    if (!map) return out;
    for (const auto& [key, value] : map->entries) {
        if (value.kind() == ValueKind::string || value.kind() == ValueKind::numeric) out.entries.emplace_back(key, value);
    }
    return out;
}

Value service_info(const Service& service, const std::string& name, const std::string& url) {
    const auto root = service.root_type();
    MapInt32 implements;
    for (std::size_t i = 0; i < root.implements.size(); ++i)
        implements.entries.emplace_back(static_cast<std::int32_t>(i), Value(root.implements[i]));
    MapInt32 urls;
    urls.entries.emplace_back(1, Value(url));
    Structure s{qualified("ServiceInfo"), {}};
    s.set("Name", Value(name));
    s.set("RootObjectType", Value(root.object_type));
    s.set("RootObjectImplements", Value(std::move(implements)));
    s.set("ConnectionURL", Value(std::move(urls)));
    s.set("Attributes", Value(index_attributes(service)));
    return Value(std::move(s));
}

class ServiceIndexService : public Service {
public:
    explicit ServiceIndexService(std::weak_ptr<Node> node) : node_(std::move(node)) {
        for (const auto* def : types_.definitions())
            if (def->name == robdef::kServiceIndexServiceName)
                for (const auto& o : def->objects)
                    if (qualified(o.name) == robdef::kServiceIndexObjectType) root_ = &o;
    }

    const std::string& name() const override { return name_; }
    std::vector<std::string> service_definitions() const override { return {std::string(robdef::service_index_robdef())}; }
    std::optional<std::string> service_definition(std::string_view type) const override {
        if (type != robdef::kServiceIndexServiceName) return std::nullopt;
        return std::string(robdef::service_index_robdef());
    }
    ObjectTypeInfo root_type() const override { return {std::string(robdef::kServiceIndexObjectType), {}}; }

    void object_type(const SessionRef&, const std::string& path, std::function<void(Result<ObjectTypeInfo>)> done) override {
        if (path != name_) return done(fail(MessageErrorType::ObjectNotFound, "Object not found: " + path));
        done(root_type());
    }

    void on_session_open(const SessionRef& session) override {
        std::lock_guard lock(mutex_);
        sessions_.push_back(session);
    }
    void on_session_close(const SessionRef& session) override {
        std::lock_guard lock(mutex_);
        std::erase(sessions_, session);
    }

    void handle_entry(const SessionRef& session, MessageEntry&& entry, Responder responder) override {
        if (entry.entry_type == MessageEntryType::PipePacket || entry.entry_type == MessageEntryType::PipePacketRet ||
            entry.entry_type == MessageEntryType::WirePacket)
            return;  // no pipes or wires here
        if (entry.service_path != name_)
            return responder.fail(make_error(MessageErrorType::ObjectNotFound, "Object not found: " + entry.service_path));
        const robdef::MemberDefinition* member = root_ ? root_->find_member(entry.member_name) : nullptr;
        if (!member)
            return responder.fail(make_error(MessageErrorType::MemberNotFound, "Member not found: " + entry.member_name));
        if (entry.entry_type != MessageEntryType::FunctionCallReq || member->kind != robdef::MemberKind::function)
            return responder.fail(make_error(MessageErrorType::MemberFormatMismatch,
                                             "Invalid operation on member " + entry.member_name));
        Value result{MapInt32{}};
        if (entry.member_name == "GetLocalNodeServices") {
            auto nodes = local_node_services(session);
            if (!nodes) return responder.fail(nodes.error());
            result = std::move(*nodes);
        }
        auto packed = pack_value(result, member->type, "return", types_, robdef::kServiceIndexServiceName);
        if (!packed) return responder.fail(packed.error());
        MessageEntry reply;
        reply.elements.push_back(std::move(*packed));
        responder.respond(std::move(reply));
    }

    void services_changed() {
        std::vector<SessionRef> sessions;
        {
            std::lock_guard lock(mutex_);
            sessions = sessions_;
        }
        MessageEntry event;
        event.entry_type = MessageEntryType::EventReq;
        event.service_path = name_;
        event.member_name = "LocalNodeServicesChanged";
        for (const auto& s : sessions) (void)s.send(event);  // a client whose queue is full misses it, as any event
    }

private:
    Result<Value> local_node_services(const SessionRef& session) const {
        auto node = node_.lock();
        if (!node) return fail(MessageErrorType::ServiceNotFound, "node is shutting down");
        std::string base = session.local_url();
        if (base.empty()) base = node->listen_base_url();
        auto names = node->service_names();
        if (std::find(names.begin(), names.end(), name_) == names.end()) names.push_back(name_);
        std::sort(names.begin(), names.end());
        MapInt32 out;
        std::int32_t key = 0;
        for (const auto& name : names) {
            auto service = node->find_service(name);
            if (!service) continue;  // unregistered meanwhile
            std::string url = base + "?nodeid=" + node->node_id().to_string() + "&service=" + name;
            out.entries.emplace_back(key++, service_info(*service, name, url));
        }
        return Value(std::move(out));
    }

    const std::string name_{robdef::kServiceIndexServiceName};
    std::weak_ptr<Node> node_;
    robdef::ServiceDefinitionSet types_;  // holds the built-in definition
    const robdef::ServiceEntryDefinition* root_ = nullptr;
    std::mutex mutex_;
    std::vector<SessionRef> sessions_;
};

}  // namespace

std::shared_ptr<Service> make_service_index(std::weak_ptr<Node> node) {
    return std::make_shared<ServiceIndexService>(std::move(node));
}

void local_node_services_changed(const std::shared_ptr<Service>& index) {
    if (auto s = std::dynamic_pointer_cast<ServiceIndexService>(index)) s->services_changed();
}

}  // namespace rr::server
