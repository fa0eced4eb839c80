// File-system side of the rr+local transport: lock files held with an fcntl write lock (CORE
// NodeDirectoriesFD::open_lock_write), entry and NodeID cache files read with a size limit, the lock
// holder of an entry, and the current user's name. Linux/Unix only.
//
// Locks are POSIX record locks (fcntl F_SETLK, F_WRLCK, whole file), the kind CORE takes: they are
// per process, so two nodes in one process do not exclude each other through them (node_identity.hpp
// adds an in-process registry for that), and they vanish when the process dies.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include <sys/types.h>

#include "base/error/rr_error.hpp"

namespace rr::server::local {

/// An open file holding a write lock on its whole content. Move-only; closing releases the lock.
class LockedFile {
public:
    LockedFile() = default;
    ~LockedFile();
    LockedFile(LockedFile&& other) noexcept;
    LockedFile& operator=(LockedFile&& other) noexcept;
    LockedFile(const LockedFile&) = delete;
    LockedFile& operator=(const LockedFile&) = delete;

    /// Opens (creating with `mode`, then set to exactly `mode` when `force_mode`) and locks `path`
    /// without waiting. If the path was replaced or removed between open and lock (a node shutting
    /// down removes its entries), tries again. Errors: InvalidOperation "in use" when another process
    /// holds the lock (the message names its pid when known); SystemResourcePermissionDenied for
    /// EACCES/EPERM; IOError otherwise (each with the path and the system message). `sys_errno`, when
    /// given, receives the errno of a failed open (0 otherwise).
    static Result<LockedFile> open_locked(const std::string& path, mode_t mode, bool force_mode, int* sys_errno = nullptr);

    /// Replaces the content with `data` (truncate, write, fsync). Errors: IOError.
    Result<void> replace(std::string_view data);
    /// Reads the whole content (at most `max_size` bytes, else IOError). Errors: IOError.
    Result<std::string> read_all(std::size_t max_size) const;
    /// File size, or IOError.
    Result<std::size_t> size() const;
    /// Removes the file from its directory (while still holding the lock), then closes it.
    void remove_and_close();
    /// Closes (releasing the lock) without removing.
    void close();

    bool is_open() const noexcept { return fd_ >= 0; }
    const std::string& path() const noexcept { return path_; }

private:
    int fd_ = -1;
    std::string path_;
};

/// Reads a small file (entry, pid, NodeID cache). Errors: ResourceNotFound (ENOENT/ENOTDIR),
/// SystemResourcePermissionDenied (EACCES/EPERM), IOError (not a regular file, larger than
/// `max_size`, other system errors); each message names the path.
Result<std::string> read_small_file(const std::string& path, std::size_t max_size);

/// The pid of the process holding a write lock on `path` (fcntl F_GETLK), nullopt when none holds it
/// or the file cannot be opened. Locks held by this process are not reported (POSIX semantics).
std::optional<pid_t> lock_holder(const std::string& path);

/// Creates `path` and its parents (mode 0777 minus the umask, as CORE). Errors: SystemResourceError
/// or SystemResourcePermissionDenied naming the path.
Result<void> make_directories(const std::string& path);

/// The name of the real user (getpwuid(getuid())), as CORE's GetLogonUserName. Errors: SystemResourceError.
Result<std::string> current_user_name();

}  // namespace rr::server::local
