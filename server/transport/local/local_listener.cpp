#include "server/transport/local/local_listener.hpp"

#include <array>

#include <sys/stat.h>
#include <unistd.h>

#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/read.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>

#include "server/common/random_ids.hpp"
#include "server/common/connection_strand.hpp"
#include "server/transport/local/local_layout.hpp"

namespace rr::server::local {

namespace asio = boost::asio;
using unix_socket = asio::local::stream_protocol;

namespace {

std::string random_alnum(std::size_t n) {
    static constexpr std::string_view kChars = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    std::string out;
    out.reserve(n);
    for (std::size_t i = 0; i < n; ++i) out.push_back(kChars[random_endpoint_id() % kChars.size()]);
    return out;
}

// The public entry directory of this user, prepared as CORE does (subdirectories setgid, mode 02750,
// group of the per-user directory the administrator made).
Result<std::string> prepare_public_dir(const NodeDirectories& dirs, const std::string& user) {
    std::string dir = public_user_dir(dirs, user);
    struct stat st {};
    if (::stat(dir.c_str(), &st) < 0 || !S_ISDIR(st.st_mode))
        return fail(MessageErrorType::SystemResourceError,
                    "this computer is not set up for public rr+local nodes: " + dir + " does not exist (an administrator creates it)");
    for (const char* sub : {"by-nodeid", "by-nodename", "socket"}) {
        std::string p = path_join(dir, sub);
        if (auto made = make_directories(p); !made) return made.take_error();
        if (::chmod(p.c_str(), S_ISGID | S_IRWXU | S_IRGRP | S_IXGRP) < 0 || ::chown(p.c_str(), ::getuid(), st.st_gid) < 0)
            return fail(MessageErrorType::SystemResourceError, "cannot set the permissions of " + p);
    }
    return dir;
}

}  // namespace

class LocalListener::Impl : public std::enable_shared_from_this<LocalListener::Impl> {
public:
    Impl(asio::any_io_executor executor, std::weak_ptr<ConnectionSink> sink, NodeID node_id, std::string node_name,
         std::chrono::milliseconds first_bytes_timeout)
        : sink_(std::move(sink)), node_id_(node_id), node_name_(std::move(node_name)),
          first_bytes_timeout_(first_bytes_timeout), acceptor_(executor), retry_(executor) {}
    ~Impl() { close(); }

    Result<void> start(LocalListenOptions options, std::optional<NodeNameReservation> reservation);
    void accept();
    void detect(unix_socket::socket socket);
    void refresh(const std::string& nonce);
    void close();
    std::vector<std::string> info_files() const {
        std::lock_guard lock(mutex_);
        std::vector<std::string> out;
        for (const auto* f : {&info_id_, &info_name_})
            if (f->is_open()) out.push_back(f->path());
        return out;
    }

    // Weak: pending accepts hold the Impl, and the Impl must never be what keeps the node (and its
    // threads) alive, or the node could be destroyed on one of its own threads.
    std::weak_ptr<ConnectionSink> sink_;
    NodeID node_id_;
    std::string node_name_;
    std::chrono::milliseconds first_bytes_timeout_;
    unix_socket::acceptor acceptor_;
    asio::steady_timer retry_;
    mutable std::mutex mutex_;
    bool closed_ = false;
    std::string socket_path_;
    std::string entry_dir_;
    InfoMap info_;
    std::optional<NodeNameReservation> reservation_;
    std::optional<InProcessClaim> id_claim_;
    LockedFile pid_id_, info_id_, pid_name_, info_name_;
};

Result<void> LocalListener::Impl::start(LocalListenOptions options, std::optional<NodeNameReservation> reservation) {
    const NodeDirectories dirs = options.dirs ? *options.dirs : default_node_directories();
    const NodeID node_id = node_id_;
    const std::string& name = node_name_;

    // 1. The NodeName (and the NodeID its cache gives it).
    if (!name.empty()) {
        if (!reservation) {
            auto r = reserve_node_name(dirs, name);
            if (!r) return r.take_error();
            reservation = std::move(*r);
        }
        if (reservation->node_name != name)
            return fail(MessageErrorType::InvalidArgument, "the reservation is for NodeName \"" + reservation->node_name +
                                                               "\", the node is named \"" + name + "\"");
        if (reservation->node_id != node_id)
            return fail(MessageErrorType::InvalidArgument,
                        "NodeName \"" + name + "\" has NodeID " + reservation->node_id.to_string() + " (" +
                            reservation->nodeid_file + ") but the node was created with NodeID " + node_id.to_string() +
                            ": create the node with the NodeID reserve_node_name() returns");
        reservation_ = std::move(reservation);
    } else if (reservation) {
        return fail(MessageErrorType::InvalidArgument, "a NodeName reservation was given for a node without a NodeName");
    }
    if (node_id.is_any()) return fail(MessageErrorType::InvalidArgument, "a node with the zero NodeID cannot serve rr+local");

    // 2. The NodeID inside this process.
    id_claim_ = InProcessClaim::take("id:" + node_id.to_string());
    if (!id_claim_)
        return fail(MessageErrorType::InvalidOperation, "NodeID " + node_id.to_string() + " is already in use in this process");

    // 3. Directories and the socket.
    auto user = current_user_name();
    if (!user) return user.take_error();
    std::string socket_dir;
    if (options.public_server) {
        auto dir = prepare_public_dir(dirs, *user);
        if (!dir) return dir.take_error();
        entry_dir_ = *dir;
        socket_dir = path_join(entry_dir_, "socket");
    } else {
        entry_dir_ = private_entry_dir(dirs);
        socket_dir = private_socket_dir(dirs);
        for (const char* sub : {"by-nodeid", "by-nodename", "socket"})
            if (auto made = make_directories(path_join(entry_dir_, sub)); !made) return made.take_error();
        if (auto made = make_directories(socket_dir); !made) return made.take_error();
    }
    boost::system::error_code ec;
    for (int tries = 0;; ++tries) {
        std::string path = path_join(socket_dir, random_alnum(16) + ".sock");
        if (path.size() > kMaxSocketPath)
            return fail(MessageErrorType::SystemResourceError,
                        "the local socket path " + path + " is longer than " + std::to_string(kMaxSocketPath) + " bytes");
        ec.clear();
        acceptor_.open(unix_socket(), ec);
        if (!ec) acceptor_.bind(unix_socket::endpoint(path), ec);
        if (!ec) socket_path_ = path;  // from here on close() removes it
        if (!ec) acceptor_.listen(asio::socket_base::max_listen_connections, ec);
        if (!ec) {
            ::chmod(path.c_str(), S_IRWXU | S_IRWXG);
            break;
        }
        boost::system::error_code ignored;
        acceptor_.close(ignored);
        if (!socket_path_.empty()) ::unlink(socket_path_.c_str());
        socket_path_.clear();
        if (tries >= 3) {
            auto type = ec == boost::system::errc::permission_denied ? MessageErrorType::SystemResourcePermissionDenied
                                                                     : MessageErrorType::SystemResourceError;
            return fail(type, "cannot listen on a local socket in " + socket_dir + ": " + ec.message());
        }
    }

    // 4. The entries.
    info_["nodename"] = name;
    info_["nodeid"] = node_id.to_braced_string();
    info_["socket"] = socket_path_;
    info_["ServiceStateNonce"] = options.service_state_nonce.empty() ? random_service_state_nonce() : options.service_state_nonce;
    info_["pid"] = std::to_string(::getpid());
    info_["username"] = *user;
    const std::string pid_text = std::to_string(::getpid());
    const std::string info_text = format_info(info_);
    auto create = [&](LockedFile& out, const std::string& path, const std::string& text, const std::string& in_use) -> Result<void> {
        auto f = LockedFile::open_locked(path, 0640, true);
        if (!f) {
            if (f.error().type == MessageErrorType::InvalidOperation) {
                auto holder = lock_holder(path);
                return fail(MessageErrorType::InvalidOperation,
                            in_use + " is already in use" + (holder ? " by process " + std::to_string(*holder) : std::string()) +
                                " (" + path + " is locked)");
            }
            return f.take_error();
        }
        out = std::move(*f);
        return out.replace(text);
    };
    const std::string id_use = "NodeID " + node_id.to_string();
    if (auto r = create(pid_id_, by_nodeid_file(entry_dir_, node_id, "pid"), pid_text, id_use); !r) return r;
    if (auto r = create(info_id_, by_nodeid_file(entry_dir_, node_id, "info"), info_text, id_use); !r) return r;
    if (!name.empty()) {
        const std::string name_use = "NodeName \"" + name + "\"";
        if (auto r = create(pid_name_, by_nodename_file(entry_dir_, name, "pid"), pid_text, name_use); !r) return r;
        if (auto r = create(info_name_, by_nodename_file(entry_dir_, name, "info"), info_text, name_use); !r) return r;
    }
    return {};
}

void LocalListener::Impl::accept() {
    auto self_ref = shared_from_this();
    acceptor_.async_accept(connection_strand(acceptor_.get_executor()),
                           [self = std::move(self_ref)](boost::system::error_code ec, unix_socket::socket socket) {
                               if (ec == asio::error::operation_aborted) return;
                               if (ec) {
                                   // Out of descriptors and the like: try again shortly instead of spinning.
                                   std::lock_guard lock(self->mutex_);
                                   if (self->closed_) return;
                                   self->retry_.expires_after(std::chrono::milliseconds(100));
                                   self->retry_.async_wait([self](boost::system::error_code wait_ec) {
                                       std::lock_guard lock2(self->mutex_);
                                       if (!wait_ec && !self->closed_) self->accept();
                                   });
                                   return;
                               }
                               {
                                   std::lock_guard lock(self->mutex_);
                                   if (self->closed_) return;
                                   self->accept();
                               }
                               self->detect(std::move(socket));
                           });
}

void LocalListener::Impl::detect(unix_socket::socket socket) {
    std::weak_ptr<ConnectionSink> weak_sink = sink_;
    auto sink = sink_.lock();
    if (!sink || !sink->can_accept()) {
        boost::system::error_code ignored;
        socket.close(ignored);  // over the connection limit: refuse without reading
        return;
    }
    struct Detect {
        unix_socket::socket socket;
        asio::steady_timer timer;
        std::array<std::byte, 4> head{};
    };
    auto ex = socket.get_executor();
    auto d = std::make_shared<Detect>(Detect{std::move(socket), asio::steady_timer(ex), {}});
    d->timer.expires_after(first_bytes_timeout_);
    d->timer.async_wait([d](boost::system::error_code ec) {
        if (!ec) {
            boost::system::error_code ignored;
            d->socket.close(ignored);  // silent for too long: drop
        }
    });
    asio::async_read(d->socket, asio::buffer(d->head), [d, weak_sink](boost::system::error_code ec, std::size_t) {
        d->timer.cancel();
        auto sink = weak_sink.lock();
        if (ec || !sink) return;
        static constexpr char kMagic[4] = {'R', 'R', 'A', 'C'};
        for (int i = 0; i < 4; ++i)
            if (d->head[i] != static_cast<std::byte>(kMagic[i])) {
                boost::system::error_code ignored;
                d->socket.close(ignored);  // not the RR stream protocol
                return;
            }
        serve_stream(*sink, std::move(d->socket), AcceptedStream{std::string(kLocalBaseUrl), "local", {}, {}},
                     std::vector<std::byte>(d->head.begin(), d->head.end()));
    });
}

void LocalListener::Impl::refresh(const std::string& nonce) {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    info_["ServiceStateNonce"] = nonce.empty() ? random_service_state_nonce(info_["ServiceStateNonce"]) : nonce;
    const std::string text = format_info(info_);
    for (auto* f : {&info_id_, &info_name_})
        if (f->is_open()) (void)f->replace(text);
}

void LocalListener::Impl::close() {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    closed_ = true;
    boost::system::error_code ignored;
    acceptor_.close(ignored);
    retry_.cancel();
    if (!socket_path_.empty()) ::unlink(socket_path_.c_str());
    // Entries go while their locks are still held, so a node starting meanwhile cannot lock a file
    // that is about to disappear (LockedFile::open_locked also re-checks the path after locking).
    info_name_.remove_and_close();
    pid_name_.remove_and_close();
    info_id_.remove_and_close();
    pid_id_.remove_and_close();
    id_claim_.reset();
    reservation_.reset();  // the NodeName lock file stays, unlocked, as CORE leaves it
}

// --- LocalListener ---------------------------------------------------------------------------------

LocalListener::LocalListener(std::shared_ptr<Impl> impl) : impl_(std::move(impl)) {
    socket_path_ = impl_->socket_path_;
    entry_dir_ = impl_->entry_dir_;
}

LocalListener::~LocalListener() {
    close();
    impl_.reset();  // a pending accept may still hold it; it never holds the node
}

Result<std::shared_ptr<LocalListener>> LocalListener::start(asio::any_io_executor executor,
                                                             std::weak_ptr<ConnectionSink> sink, const NodeID& node_id,
                                                             const std::string& node_name, LocalListenOptions options,
                                                             std::optional<NodeNameReservation> reservation) {
    auto impl = std::make_shared<Impl>(std::move(executor), std::move(sink), node_id, node_name, options.first_bytes_timeout);
    if (auto r = impl->start(std::move(options), std::move(reservation)); !r) {
        impl->close();
        return r.take_error();
    }
    {
        std::lock_guard lock(impl->mutex_);
        impl->accept();
    }
    return std::shared_ptr<LocalListener>(new LocalListener(std::move(impl)));
}

std::string LocalListener::url() const { return local_listen_url(impl_->node_id_); }

std::vector<std::string> LocalListener::info_files() const { return impl_->info_files(); }

void LocalListener::refresh_service_state(const std::string& nonce) { impl_->refresh(nonce); }

std::string LocalListener::service_state_nonce() const {
    std::lock_guard lock(impl_->mutex_);
    auto it = impl_->info_.find("ServiceStateNonce");
    return it == impl_->info_.end() ? std::string() : it->second;
}

void LocalListener::close() {
    if (impl_) impl_->close();
}

}  // namespace rr::server::local
