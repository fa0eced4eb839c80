// The JSON API's operations (docs/json-api.md), shared by the REST routes (json_rest.hpp) and the JSON
// WebSocket (json_socket.hpp): list and describe devices, get/set properties, call functions (generators
// collected into a list), peek wires. Values travel as JSON per docs/json-mapping.md, typed by the
// device's own service definitions.
//
// Requests go to the device through DeviceMirror::request on the gateway's own upstream session, with
// service paths in gateway naming: the root object is `<device>`, an object below it
// `<device>.<relative path>` (relative paths such as `Webcams[0]` are resolved with ObjectTypeName to
// learn the object's type).
//
// Thread-safety: every function may be called from any thread; `done` callbacks run on the device
// connection's strand (or inline when the request fails before reaching the device) and must not block.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "base/codec/limits.hpp"
#include "core/json/value_json.hpp"
#include "base/names/object_path.hpp"
#include "server/gateway/auth/gateway_auth.hpp"
#include "server/gateway/device_mirror.hpp"
#include "server/gateway/device_types.hpp"
#include "server/gateway/json_api_error.hpp"
#include "server/gateway/motion_guard.hpp"

namespace rr::server::gateway {

/// Which member a request is about.
struct MemberAddress {
    std::string device;
    std::string object;  ///< relative service path below the root object ("" = the root), e.g. `Webcams[0]`
    std::string member;
    /// Who asks (auth: gateway): checked against the gateway's policy when logins are on.
    auth::PrincipalPtr principal;
    /// auth: passthrough: the client's own session to the device (DeviceMirror::open_api_session), so
    /// the device's users, privileges and locks apply; 0 = the gateway's shared session.
    std::uint32_t device_session = 0;
    /// Motion safety (motion_guard.hpp): the caller as the device's motion guard sees it (who holds a
    /// motion, whose going away ends it); null: an anonymous caller that holds nothing beyond its request.
    std::shared_ptr<const MotionClient> motion;
    /// The caller's motions end with its request (plain HTTP): a motion without a timeout of its own
    /// whose call does not wait for its end (wait false) is refused with 409.
    bool motion_waits_only = false;
};

/// A member resolved against the device's definitions. The pointers point into `types`.
struct MemberTarget {
    std::shared_ptr<DeviceMirror> device;
    std::shared_ptr<const DeviceTypes> types;
    std::string path;  ///< service path in gateway naming
    std::string object_type;
    const robdef::ServiceDefinition* service = nullptr;  ///< defines the object (context for unqualified names)
    const robdef::ServiceEntryDefinition* object = nullptr;
    const robdef::MemberDefinition* member = nullptr;
    /// Where get/set/call/peek go: MemberAddress::device_session (0 = the shared session).
    std::uint32_t device_session = 0;
    /// The gateway user the request acts as (Principal::rr_user_name of MemberAddress::principal; ""
    /// without logins), for the locks held at the gateway (JsonApi::check_locks).
    std::string user;

    std::string_view context() const noexcept { return service->name; }
};

using Resolved = std::variant<MemberTarget, ApiError>;

struct JsonApiOptions {
    /// Generator items collected by one call when the request names no `max_items`.
    std::size_t default_max_items = 100;
    /// Largest `max_items` accepted (400 above).
    std::size_t max_items_limit = 10000;
    /// Limits for value conversions (nesting depth, sizes).
    Limits limits;
};

/// A relative object path (`object=`) in RR service-path form: base/names/object_path.hpp.
using ::rr::normalize_object_path;

class JsonApi : public std::enable_shared_from_this<JsonApi> {
public:
    using Done = std::function<void(ApiResult)>;

    explicit JsonApi(std::vector<std::shared_ptr<DeviceMirror>> devices, JsonApiOptions options = {});

    /// The devices now (configured ones first, then those added while running), a snapshot.
    std::vector<std::shared_ptr<DeviceMirror>> devices() const;
    const JsonApiOptions& options() const noexcept { return options_; }
    std::shared_ptr<DeviceMirror> find_device(std::string_view name) const;

    /// A device added while running (discovery, the "add" action): listed and reachable from now on.
    /// Errors: InvalidArgument when the name is taken.
    Result<void> add_device(std::shared_ptr<DeviceMirror> device);
    /// Removes a device added while running; returns it (nullptr when unknown). The caller stops it.
    std::shared_ptr<DeviceMirror> remove_device(std::string_view name);
    /// Told (without locks held) after add_device (`added` true) and remove_device (false).
    using DevicesListener = std::function<void(const std::shared_ptr<DeviceMirror>& device, bool added)>;
    std::uint64_t add_devices_listener(DevicesListener listener);
    void remove_devices_listener(std::uint64_t id);

    /// What discovery offers the API (docs/json-api.md "Discovery"): the list of discovered nodes and
    /// services, and turning a discovered service into a device. Unset: those routes answer 404.
    struct DiscoveryHooks {
        std::function<nlohmann::json()> list;
        /// Body `{"nodeid", "service", "name"?}`; `done` gets the new device's status_json or an error.
        std::function<void(const nlohmann::json& body, Done done)> add;
    };
    void set_discovery_hooks(DiscoveryHooks hooks);
    DiscoveryHooks discovery_hooks() const;

    /// `{"name", "url", "state", "reason", "object_type", "required", "clients", "auth", "locks"}` of one
    /// device, and a passthrough device's `passthrough_sessions` and `json_api_requires_device_login`.
    static nlohmann::json status_json(const DeviceStatus& status);
    /// GET /api/devices: `[status_json…]`, in configuration order.
    nlohmann::json device_list() const;
    /// GET /api/devices/{name}: status_json plus `definitions` (texts) and `members` (member_summary of
    /// the root object; empty before the first connect). Errors: 404.
    ApiResult device_info(std::string_view name) const;
    /// GET /api/devices/{name}/definitions: `{"definitions": [texts]}`. Errors: 404.
    ApiResult definitions(std::string_view name) const;

    /// The gateway's users and permissions (docs/security.md): when they are enabled, get/set/call/peek
    /// need a principal in the MemberAddress (401 without) whose roles allow the operation (403
    /// PermissionDenied otherwise). Set before serving.
    void set_auth(std::shared_ptr<auth::GatewayAuth> auth) { auth_ = std::move(auth); }
    const std::shared_ptr<auth::GatewayAuth>& auth() const noexcept { return auth_; }
    /// The check itself: nothing when allowed (or logins are off), else 401 / 403.
    std::optional<ApiError> check_access(const MemberAddress& address, auth::Operation op) const;

    /// The locks held at the gateway on an `auth: shared` device (docs/security.md "auth: shared"): a
    /// JSON API request has no session of its own, so it passes only the user locks of its user
    /// (`target.user`), never a client lock or another session's monitor; a `[nolock]` member (and a
    /// `[nolockread]` one for `PropertyGetReq`) passes object locks. `type` is the RR request the
    /// operation makes. Nothing when it may go on (always on the device's own session of a
    /// `device_login`); else 409 with ObjectLockedError ("Object locked by alice") or InvalidOperation
    /// (a monitor).
    std::optional<ApiError> check_locks(const MemberTarget& target, MessageEntryType type) const;

    /// The motion guard's decision on `call` (a FunctionCallReq, PropertySetReq or WirePacket for
    /// `target`) made by `address`'s caller (docs/security.md "Motion safety"): nothing to follow
    /// (nullopt ticket, `stop` false), a stop (passes the locks), or a motion to follow with
    /// finish_motion(). Errors: 409 (held by another client; wait false over plain HTTP), 400 (a
    /// hold-to-run call without a numeric timeout).
    struct MotionAdmission {
        std::shared_ptr<MotionGuard> guard;
        MotionClient client;
        std::optional<MotionGuard::Ticket> ticket;
        bool stop = false;
        std::int32_t generator_index = -1;  ///< a generator motion's index, once the device answered
    };
    static std::variant<MotionAdmission, ApiError> admit_motion(const MemberAddress& address, const MemberTarget& target,
                                                                MessageEntry& call);
    /// The device's answer to an admitted motion.
    static void finish_motion(const MotionAdmission& m, const Result<MessageEntry>& reply);

    /// Finds device, object and member. Errors: 404 (unknown device / object / member), 400 (malformed
    /// object path), 503 (device not connected), 502 (definitions unusable), 504.
    void resolve(const MemberAddress& address, std::function<void(Resolved)> done);

    /// `{"value": …}`. Errors: as resolve; 404 not a property; 405 writeonly; device errors.
    void get_property(const MemberAddress& address, Done done);
    /// `{}`. Errors: as resolve; 400 value does not fit; 405 readonly; device errors.
    void set_property(const MemberAddress& address, const nlohmann::json& value, Done done);
    /// `{"return": …}` (null for void); generator functions: `{"items": […]}` with at most `max_items`
    /// items (0 = options().default_max_items), the generator closed afterwards. `args` is an array
    /// (positional), an object (by parameter name) or null (no parameters); a generator parameter takes
    /// an array of items, each sent with one GeneratorNextReq.
    void call_function(const MemberAddress& address, const nlohmann::json& args, std::size_t max_items, Done done);
    /// `{"value": …, "time": {"seconds", "nanoseconds"}}`: the newest value of a wire (WirePeekInValue).
    void peek_wire(const MemberAddress& address, Done done);

    /// The element as JSON for `type` of `target`'s service; with `binary`, numeric arrays go there
    /// (value_json.hpp BinaryArrays). Errors: 502 (the device sent a value that does not fit its own
    /// definition).
    ApiResult element_json(const MessageElement& element, const robdef::TypeDefinition& type,
                           const MemberTarget& target, BinaryArrays* binary = nullptr) const;
    /// JSON as an element named `name` packed for `type`. Errors: 400 (value_error, `where` names it).
    Result<MessageElement> element_from_json(const nlohmann::json& json, const robdef::TypeDefinition& type,
                                             const MemberTarget& target, std::string_view name,
                                             ApiError& error, std::string_view where) const;
    /// The device's parsed definitions (cached while the texts stay the same), or nullptr when unusable.
    std::shared_ptr<const DeviceTypes> types_for(const DeviceMirror& device, ApiError* error = nullptr) const;

private:
    void finish_resolve(std::shared_ptr<DeviceMirror> device, std::shared_ptr<const DeviceTypes> types,
                        std::string path, std::string object_type, std::string member,
                        const std::function<void(Resolved)>& done) const;

    std::vector<std::shared_ptr<DeviceMirror>> devices_;  // guarded by mutex_
    JsonApiOptions options_;
    mutable std::mutex mutex_;
    std::map<std::uint64_t, DevicesListener> devices_listeners_;
    std::uint64_t next_devices_listener_ = 1;
    DiscoveryHooks discovery_hooks_;
    std::shared_ptr<auth::GatewayAuth> auth_;
    mutable std::map<const DeviceMirror*, std::shared_ptr<const DeviceTypes>> types_;
};

/// `{"seconds": s, "nanoseconds": ns}`.
nlohmann::json time_json(std::int64_t seconds, std::int32_t nanoseconds);

/// Deepest nesting of arrays/objects accepted in a request (the JSON mapping itself stops at
/// Limits::max_nesting_depth, 64).
inline constexpr std::size_t kMaxRequestJsonDepth = 100;

/// Parses a request body or WebSocket message. Errors: InvalidArgument with the parser's message, or
/// when arrays/objects nest deeper than kMaxRequestJsonDepth (checked before parsing).
Result<nlohmann::json> parse_request_json(std::string_view text);

}  // namespace rr::server::gateway
