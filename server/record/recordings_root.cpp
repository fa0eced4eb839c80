#include "server/record/recordings_root.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "server/record/recording_spec.hpp"

namespace rr::server::record {

namespace fs = std::filesystem;

namespace {

Unexpected io_error(const std::string& what, int err) {
    return fail(MessageErrorType::IOError, "record: " + what + ": " + std::strerror(err));
}

std::string absolute_path(const std::string& path) {
    std::error_code ec;
    auto abs = fs::absolute(path, ec);
    return (ec ? fs::path(path) : abs).lexically_normal().string();
}

std::string mib(std::uint64_t bytes) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
    return buf;
}

}  // namespace

// --- RecordingsFolder --------------------------------------------------------------------------------

RecordingsFolder::~RecordingsFolder() {
    if (fd_ >= 0) ::close(fd_);
}

Result<std::unique_ptr<mcap::FileSink>> RecordingsFolder::create_file(std::string_view name, bool* exists) {
    if (exists) *exists = false;
    const std::string n(name);
    if (n.empty() || n.find('/') != std::string::npos || n.find('\0') != std::string::npos || n.front() == '.')
        return fail(MessageErrorType::InvalidArgument, "record: not a plain file name: " + n);
    int fd = ::openat(fd_, n.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0640);
    if (fd < 0) {
        const int err = errno;
        if (exists) *exists = err == EEXIST;
        return io_error("cannot create " + path_of(n), err);
    }
    return mcap::FileSink::adopt(fd, path_of(n));
}

Result<void> RecordingsFolder::remove_file(std::string_view name) {
    const std::string n(name);
    if (n.empty() || n.find('/') != std::string::npos || n.front() == '.')
        return fail(MessageErrorType::InvalidArgument, "record: not a plain file name: " + n);
    if (::unlinkat(fd_, n.c_str(), 0) != 0) return io_error("cannot remove " + path_of(n), errno);
    return {};
}

// --- RecordingsRoot ----------------------------------------------------------------------------------

RecordingsRoot::RecordingsRoot(std::string path, std::uint64_t max_total_bytes)
    : path_(absolute_path(path)), max_total_(max_total_bytes) {}

Result<std::unique_ptr<RecordingsFolder>> RecordingsRoot::open_folder(std::string_view subfolder) {
    if (auto r = check_subfolder(subfolder); !r) return r.take_error();
    std::error_code ec;
    fs::create_directories(path_, ec);  // the operator's folder: its parents and links are theirs
    if (ec) return fail(MessageErrorType::IOError, "record: cannot create the recordings root " + path_ + ": " + ec.message());
    int dir = ::open(path_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir < 0) return io_error("cannot open the recordings root " + path_, errno);
    std::string shown = path_;
    std::size_t pos = 0;
    while (pos < subfolder.size()) {
        const auto slash = subfolder.find('/', pos);
        const std::string part(subfolder.substr(pos, slash == std::string_view::npos ? std::string_view::npos : slash - pos));
        pos = slash == std::string_view::npos ? subfolder.size() : slash + 1;
        shown += "/" + part;
        if (::mkdirat(dir, part.c_str(), 0750) != 0 && errno != EEXIST) {
            const int err = errno;
            ::close(dir);
            return io_error("cannot create " + shown, err);
        }
        const int next = ::openat(dir, part.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
        const int err = errno;
        // A link fails with ELOOP or, as O_DIRECTORY is checked first on some kernels, ENOTDIR: tell which.
        struct stat st {};
        const bool link = next < 0 && ::fstatat(dir, part.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 && S_ISLNK(st.st_mode);
        ::close(dir);
        if (next < 0) {
            if (link || err == ELOOP)
                return fail(MessageErrorType::IOError,
                            "record: " + shown + " is a symbolic link (links below the recordings root are not followed)");
            if (err == ENOTDIR) return fail(MessageErrorType::IOError, "record: " + shown + " is not a folder");
            return io_error("cannot open " + shown, err);
        }
        dir = next;
    }
    return std::make_unique<RecordingsFolder>(dir, shown);
}

std::uint64_t RecordingsRoot::bytes_below(const std::string& path) {
    std::uint64_t total = 0;
    std::error_code ec;
    fs::recursive_directory_iterator it(path, fs::directory_options::skip_permission_denied, ec);
    if (ec) return 0;
    std::size_t entries = 0;
    for (; it != fs::recursive_directory_iterator() && entries < 100000; it.increment(ec), ++entries) {
        if (ec) break;
        if (it.depth() >= 32) it.disable_recursion_pending();
        const auto st = it->symlink_status(ec);  // links are not followed (nor counted)
        if (ec || st.type() != fs::file_type::regular) continue;
        struct stat s {};
        if (::lstat(it->path().c_str(), &s) == 0 && S_ISREG(s.st_mode)) total += static_cast<std::uint64_t>(s.st_size);
    }
    return total;
}

std::uint64_t RecordingsRoot::set_aside_locked(const Admission* except) const {
    std::uint64_t n = 0;
    for (const auto* a : admitted_)
        if (a != except && a->set_aside_ > a->written_) n += a->set_aside_ - a->written_;
    return n;
}

std::uint64_t RecordingsRoot::used_bytes() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return static_cast<std::uint64_t>(std::max<std::int64_t>(used_, 0));
}

Result<std::shared_ptr<RecordingsRoot::Admission>> RecordingsRoot::admit(std::uint64_t own_budget, std::uint64_t at_least) {
    const std::uint64_t counted = bytes_below(path_);  // outside the lock: writers go on meanwhile
    std::lock_guard<std::mutex> lock(mutex_);
    used_ = static_cast<std::int64_t>(counted);
    const std::uint64_t need = own_budget ? own_budget : at_least;
    if (max_total_) {
        const std::uint64_t aside = set_aside_locked(nullptr);
        if (need > max_total_ || counted + aside > max_total_ - need)
            return fail(MessageErrorType::OutOfSystemResource,
                        "record: the recordings root " + path_ + " would pass its budget of " + std::to_string(max_total_) + " bytes (" +
                            mib(max_total_) + ", recordings.max_total_bytes): " + std::to_string(counted) + " bytes used, " +
                            std::to_string(aside) + " set aside by running recordings, this one needs " + std::to_string(need) +
                            (own_budget ? " (its max_total_bytes)" : ""));
    }
    std::shared_ptr<Admission> a(new Admission(shared_from_this(), own_budget));
    admitted_.push_back(a.get());
    return a;
}

RecordingsRoot::Admission::~Admission() {
    std::lock_guard<std::mutex> lock(root_->mutex_);
    root_->admitted_.remove(this);
}

bool RecordingsRoot::Admission::note(std::int64_t delta) {
    auto& r = *root_;
    std::lock_guard<std::mutex> lock(r.mutex_);
    r.used_ += delta;
    written_ = static_cast<std::uint64_t>(std::max<std::int64_t>(static_cast<std::int64_t>(written_) + delta, 0));
    if (!r.max_total_) return true;
    const auto used = static_cast<std::uint64_t>(std::max<std::int64_t>(r.used_, 0));
    return used + r.set_aside_locked(this) <= r.max_total_;
}

}  // namespace rr::server::record
