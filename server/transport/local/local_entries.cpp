#include "server/transport/local/local_entries.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include <fcntl.h>
#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

namespace rr::server::local {

namespace {

std::string sys_message(int err) { return std::strerror(err); }

RRError file_error(int err, const std::string& what, const std::string& path) {
    MessageErrorType type = MessageErrorType::IOError;
    if (err == ENOENT || err == ENOTDIR) type = MessageErrorType::ResourceNotFound;
    if (err == EACCES || err == EPERM) type = MessageErrorType::SystemResourcePermissionDenied;
    return make_error(type, what + " " + path + ": " + sys_message(err));
}

bool write_all(int fd, std::string_view data) {
    while (!data.empty()) {
        ssize_t n = ::write(fd, data.data(), data.size());
        if (n < 0) {
            if (errno == EINTR) continue;
            return false;
        }
        data.remove_prefix(static_cast<std::size_t>(n));
    }
    return true;
}

}  // namespace

LockedFile::~LockedFile() { close(); }

LockedFile::LockedFile(LockedFile&& other) noexcept : fd_(other.fd_), path_(std::move(other.path_)) { other.fd_ = -1; }

LockedFile& LockedFile::operator=(LockedFile&& other) noexcept {
    if (this != &other) {
        close();
        fd_ = other.fd_;
        path_ = std::move(other.path_);
        other.fd_ = -1;
    }
    return *this;
}

Result<LockedFile> LockedFile::open_locked(const std::string& path, mode_t mode, bool force_mode, int* sys_errno) {
    if (sys_errno) *sys_errno = 0;
    for (int attempt = 0; attempt < 5; ++attempt) {
        int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, mode);
        if (fd < 0) {
            if (sys_errno) *sys_errno = errno;
            return fail(file_error(errno, "cannot open", path));
        }
        struct flock lk {};
        lk.l_type = F_WRLCK;
        lk.l_whence = SEEK_SET;
        lk.l_start = 0;
        lk.l_len = 0;
        if (::fcntl(fd, F_SETLK, &lk) < 0) {
            int err = errno;
            std::string holder;
            if (err == EACCES || err == EAGAIN) {
                struct flock q {};
                q.l_type = F_WRLCK;
                q.l_whence = SEEK_SET;
                if (::fcntl(fd, F_GETLK, &q) == 0 && q.l_type != F_UNLCK) holder = " by process " + std::to_string(q.l_pid);
                ::close(fd);
                return fail(MessageErrorType::InvalidOperation, path + " is in use (locked" + holder + ")");
            }
            ::close(fd);
            return fail(file_error(err, "cannot lock", path));
        }
        // The file may have been removed (or replaced) by its previous holder between our open and our
        // lock: then the lock is on a dead inode. Check and start over.
        struct stat by_fd {}, by_path {};
        if (::fstat(fd, &by_fd) == 0 && ::stat(path.c_str(), &by_path) == 0 && by_fd.st_ino == by_path.st_ino &&
            by_fd.st_dev == by_path.st_dev) {
            if (force_mode) (void)::fchmod(fd, mode);
            LockedFile f;
            f.fd_ = fd;
            f.path_ = path;
            return f;
        }
        ::close(fd);
    }
    return fail(MessageErrorType::IOError, "cannot lock " + path + ": it keeps being replaced");
}

Result<void> LockedFile::replace(std::string_view data) {
    if (fd_ < 0) return fail(MessageErrorType::IOError, "file not open");
    if (::ftruncate(fd_, 0) < 0 || ::lseek(fd_, 0, SEEK_SET) < 0 || !write_all(fd_, data) || ::fsync(fd_) < 0)
        return fail(file_error(errno, "cannot write", path_));
    return {};
}

Result<std::size_t> LockedFile::size() const {
    struct stat st {};
    if (fd_ < 0 || ::fstat(fd_, &st) < 0) return fail(file_error(errno, "cannot stat", path_));
    return static_cast<std::size_t>(st.st_size);
}

Result<std::string> LockedFile::read_all(std::size_t max_size) const {
    auto n = size();
    if (!n) return n.take_error();
    if (*n > max_size) return fail(MessageErrorType::IOError, path_ + " is larger than " + std::to_string(max_size) + " bytes");
    std::string out(*n, '\0');
    std::size_t got = 0;
    while (got < out.size()) {
        ssize_t r = ::pread(fd_, out.data() + got, out.size() - got, static_cast<off_t>(got));
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) return fail(file_error(errno, "cannot read", path_));
        if (r == 0) break;
        got += static_cast<std::size_t>(r);
    }
    out.resize(got);
    return out;
}

void LockedFile::remove_and_close() {
    if (fd_ >= 0) (void)::unlink(path_.c_str());
    close();
}

void LockedFile::close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
}

Result<std::string> read_small_file(const std::string& path, std::size_t max_size) {
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) return fail(file_error(errno, "cannot open", path));
    struct stat st {};
    if (::fstat(fd, &st) < 0) {
        int err = errno;
        ::close(fd);
        return fail(file_error(err, "cannot stat", path));
    }
    if (!S_ISREG(st.st_mode)) {
        ::close(fd);
        return fail(MessageErrorType::IOError, path + " is not a regular file");
    }
    if (static_cast<std::uint64_t>(st.st_size) > max_size) {
        ::close(fd);
        return fail(MessageErrorType::IOError, path + " is larger than " + std::to_string(max_size) + " bytes");
    }
    std::string out(static_cast<std::size_t>(st.st_size), '\0');
    std::size_t got = 0;
    while (got < out.size()) {
        ssize_t r = ::read(fd, out.data() + got, out.size() - got);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            int err = errno;
            ::close(fd);
            return fail(file_error(err, "cannot read", path));
        }
        if (r == 0) break;
        got += static_cast<std::size_t>(r);
    }
    ::close(fd);
    out.resize(got);
    return out;
}

std::optional<pid_t> lock_holder(const std::string& path) {
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) return std::nullopt;
    struct flock q {};
    q.l_type = F_WRLCK;
    q.l_whence = SEEK_SET;
    std::optional<pid_t> out;
    if (::fcntl(fd, F_GETLK, &q) == 0 && q.l_type != F_UNLCK) out = q.l_pid;
    ::close(fd);
    return out;
}

Result<void> make_directories(const std::string& path) {
    std::error_code ec;
    std::filesystem::create_directories(path, ec);
    if (ec) {
        auto type = (ec == std::errc::permission_denied || ec == std::errc::operation_not_permitted)
                        ? MessageErrorType::SystemResourcePermissionDenied
                        : MessageErrorType::SystemResourceError;
        return fail(type, "cannot create directory " + path + ": " + ec.message());
    }
    return {};
}

Result<std::string> current_user_name() {
    long size = ::sysconf(_SC_GETPW_R_SIZE_MAX);
    std::vector<char> buf(size > 0 ? static_cast<std::size_t>(size) : 16384);
    struct passwd pw {};
    struct passwd* found = nullptr;
    int err = ::getpwuid_r(::getuid(), &pw, buf.data(), buf.size(), &found);
    if (err != 0 || !found || !found->pw_name || !*found->pw_name)
        return fail(MessageErrorType::SystemResourceError,
                    "cannot determine the current user (uid " + std::to_string(::getuid()) + ")");
    return std::string(found->pw_name);
}

}  // namespace rr::server::local
