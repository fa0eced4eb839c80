#include "server/transport/local/node_identity.hpp"

#include <mutex>
#include <set>

#include <cerrno>

#include <unistd.h>

#include "server/common/random_ids.hpp"
#include "server/transport/local/local_layout.hpp"

namespace rr::server::local {

namespace {

struct Claims {
    std::mutex mutex;
    std::set<std::string, std::less<>> keys;
};

Claims& claims() {
    static Claims c;
    return c;
}

std::string parent_of(const std::string& path) {
    auto slash = path.rfind('/');
    return slash == std::string::npos || slash == 0 ? std::string(slash == 0 ? "/" : ".") : path.substr(0, slash);
}

std::string_view trim_ws(std::string_view s) {
    auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; };
    while (!s.empty() && blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && blank(s.back())) s.remove_suffix(1);
    return s;
}

Result<NodeID> parse_cached_id(std::string_view text, const std::string& path) {
    auto id = NodeID::parse(trim_ws(text));
    if (!id || id->is_any())
        return fail(MessageErrorType::IOError, "the NodeID cache file " + path + " does not hold a NodeID");
    return *id;
}

// Reads the NodeID from a locked cache file, writing a fresh one into an empty file.
Result<NodeID> load_or_create(LockedFile& f, const NodeID& wanted) {
    auto size = f.size();
    if (!size) return size.take_error();
    if (*size == 0) {
        NodeID id = wanted.is_any() ? random_node_id() : wanted;
        auto w = f.replace(id.to_braced_string());
        if (!w) return w.take_error();
        return id;
    }
    auto text = f.read_all(kMaxEntryFileSize);
    if (!text) return text.take_error();
    return parse_cached_id(*text, f.path());
}

}  // namespace

InProcessClaim::~InProcessClaim() {
    if (key_.empty()) return;
    auto& c = claims();
    std::lock_guard lock(c.mutex);
    c.keys.erase(key_);
}

InProcessClaim& InProcessClaim::operator=(InProcessClaim&& o) noexcept {
    if (this != &o) {
        InProcessClaim old(std::move(*this));
        key_ = std::move(o.key_);
        o.key_.clear();
    }
    return *this;
}

std::optional<InProcessClaim> InProcessClaim::take(std::string key) {
    auto& c = claims();
    std::lock_guard lock(c.mutex);
    if (!c.keys.insert(key).second) return std::nullopt;
    InProcessClaim out;
    out.key_ = std::move(key);
    return out;
}

Result<NodeNameReservation> reserve_node_name(const NodeDirectories& dirs, std::string_view name, const NodeID& wanted) {
    if (!is_valid_node_name(name))
        return fail(MessageErrorType::InvalidArgument,
                    "\"" + std::string(name) + "\" is an invalid NodeName (letters, digits, '_', '.', '-', starting with a letter)");
    NodeNameReservation r;
    r.node_name = std::string(name);
    auto claim = InProcessClaim::take("name:" + r.node_name);
    if (!claim)
        return fail(MessageErrorType::InvalidOperation, "NodeName \"" + r.node_name + "\" is already in use in this process");
    r.claim = std::move(*claim);

    const std::string lock_path = nodename_lock_file(dirs, name);
    if (auto made = make_directories(parent_of(lock_path)); !made) return made.take_error();
    auto lock = LockedFile::open_locked(lock_path, 0660, false);
    if (!lock) {
        if (lock.error().type == MessageErrorType::InvalidOperation) {
            auto holder = lock_holder(lock_path);
            return fail(MessageErrorType::InvalidOperation,
                        "NodeName \"" + r.node_name + "\" is already in use" +
                            (holder ? " by process " + std::to_string(*holder) : std::string()) + " (lock " + lock_path + ")");
        }
        return lock.take_error();
    }
    r.lock = std::move(*lock);
    if (auto w = r.lock.replace(std::to_string(::getpid())); !w) return w.take_error();

    if (dirs.user_config_dir.empty())
        return fail(MessageErrorType::SystemResourceError,
                    "cannot find the NodeID cache for NodeName \"" + r.node_name +
                        "\": the user config directory is unknown (HOME is not set; set ROBOTRACONTEUR_USER_CONFIG_DIR)");
    const bool root = ::getuid() == 0;
    const std::string config_file = nodeid_cache_file(dirs, name);
    // CORE creates <user config>/nodeids for root too (/etc/robotraconteur/nodeids), where it only reads.
    if (auto made = make_directories(parent_of(config_file)); !made && !root) return made.take_error();
    if (root) {
        // Root reads a NodeID an administrator placed in the system config dir, else keeps it in the
        // state dir (CORE: /etc/robotraconteur/nodeids, /var/lib/robotraconteur/nodeids).
        auto text = read_small_file(config_file, kMaxEntryFileSize);
        if (text) {
            auto id = parse_cached_id(*text, config_file);
            if (!id) return id.take_error();
            r.node_id = *id;
            r.nodeid_file = config_file;
            return r;
        }
        if (text.error().type != MessageErrorType::ResourceNotFound) return text.take_error();
    }
    const std::string file = root ? nodeid_state_file(dirs, name) : config_file;
    if (root)
        if (auto made = make_directories(parent_of(file)); !made) return made.take_error();
    int open_errno = 0;
    auto f = LockedFile::open_locked(file, 0660, false, &open_errno);
    if (!f) {
        if (open_errno == EROFS) {
            // CORE falls back to reading on a read-only file system.
            auto text = read_small_file(file, kMaxEntryFileSize);
            if (!text) return fail(MessageErrorType::InvalidOperation, "NodeID for \"" + r.node_name + "\" not set on a read-only file system");
            auto id = parse_cached_id(*text, file);
            if (!id) return id.take_error();
            r.node_id = *id;
            r.nodeid_file = file;
            return r;
        }
        return f.take_error();
    }
    auto id = load_or_create(*f, wanted);
    if (!id) return id.take_error();
    r.node_id = *id;
    r.nodeid_file = file;
    return r;
}

}  // namespace rr::server::local
