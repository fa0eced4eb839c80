// The recordings root (docs/recording.md "Where recordings go"): the one folder every recording of the
// gateway writes below, the sub-folders and files made in it, and the disk budget of all of it.
//
// Confinement: a sub-folder (check_subfolder, recording_spec.hpp: relative parts, none starting with a
// dot) is walked part by part from a descriptor of the root, each part opened with
// openat(O_DIRECTORY|O_NOFOLLOW) and made with mkdirat (mode 0750) when missing, so a symbolic link
// planted anywhere below the root is refused, never followed. Files are made through the folder's
// descriptor with O_CREAT|O_EXCL|O_NOFOLLOW, mode 0640: never an existing file, never through a link.
// A recording removes (its own disk budget) only names it made, through the same descriptor. The root
// itself is the operator's choice: it is made with its parents when missing, and may be a link.
//
// Budget: the bytes of the regular files below the root (counted by walking it, without following
// links, each time a recording is admitted) plus what admitted recordings write since, against
// max_total_bytes; a recording with a disk budget of its own (RecordingSpec::max_total_bytes) has
// that much set aside for it while it runs.
//
// Thread-safe. Everything here touches the disk: the gateway calls it from a recording's writer
// thread, never from an HTTP thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

#include "base/error/rr_error.hpp"
#include "server/mcap/mcap_file.hpp"

namespace rr::server::record {

/// A folder below the root, open: files are made and removed through its descriptor only.
class RecordingsFolder {
public:
    RecordingsFolder(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
    ~RecordingsFolder();
    RecordingsFolder(const RecordingsFolder&) = delete;
    RecordingsFolder& operator=(const RecordingsFolder&) = delete;

    /// The folder's path as shown to users (the root's absolute path, then the sub-folder).
    const std::string& path() const noexcept { return path_; }
    std::string path_of(std::string_view name) const { return path_ + "/" + std::string(name); }

    /// Makes the file `name` (a plain name, no '/') with O_CREAT|O_EXCL|O_NOFOLLOW, mode 0640. Errors:
    /// IOError naming the path and the reason; `*exists` (when given) is set when the name was taken.
    Result<std::unique_ptr<mcap::FileSink>> create_file(std::string_view name, bool* exists = nullptr);
    /// Removes the file `name` of this folder (not following a link: a link is removed itself).
    Result<void> remove_file(std::string_view name);

private:
    int fd_ = -1;
    std::string path_;
};

class RecordingsRoot : public std::enable_shared_from_this<RecordingsRoot> {
public:
    /// One admitted recording's share of the budget; gives it back when destroyed.
    class Admission {
    public:
        ~Admission();
        /// The recording's files grew (delta > 0) or lost files (delta < 0) by `delta` bytes. Returns
        /// false when the root's budget is used up: the bytes below the root and what the other
        /// admitted recordings have set aside pass max_total_bytes.
        bool note(std::int64_t delta);

    private:
        friend class RecordingsRoot;
        Admission(std::shared_ptr<RecordingsRoot> root, std::uint64_t set_aside) : root_(std::move(root)), set_aside_(set_aside) {}
        std::shared_ptr<RecordingsRoot> root_;
        const std::uint64_t set_aside_;  // its own disk budget (0: none)
        std::uint64_t written_ = 0;      // what its files hold now (guarded by the root's mutex)
    };

    /// `path`: made absolute now (relative to the working directory); created on first use.
    /// `max_total_bytes`: 0 = no budget (`rr record`, writing on its user's own computer).
    RecordingsRoot(std::string path, std::uint64_t max_total_bytes);

    const std::string& path() const noexcept { return path_; }
    std::uint64_t max_total_bytes() const noexcept { return max_total_; }

    /// Opens `subfolder` ("" = the root; checked by check_subfolder first), making the root and each
    /// missing part. Errors: InvalidArgument (a bad sub-folder), IOError naming the folder and the
    /// reason: "… is a symbolic link (links below the recordings root are not followed)", "… is not a
    /// folder", the system's reason.
    Result<std::unique_ptr<RecordingsFolder>> open_folder(std::string_view subfolder);

    /// Admits a recording that sets aside `own_budget` bytes (0: none; it then needs `at_least` free
    /// now): walks the root for the bytes below it, adds what the running admitted recordings have set
    /// aside and not yet written, and refuses with OutOfSystemResource, the numbers in the message,
    /// when this one would pass max_total_bytes.
    Result<std::shared_ptr<Admission>> admit(std::uint64_t own_budget, std::uint64_t at_least);

    /// The bytes below the root as counted (the last walk plus what recordings wrote since).
    std::uint64_t used_bytes() const;

    /// Walks the folder at `path` without following links (at most 100,000 entries, 32 levels) and
    /// returns the bytes of its regular files; 0 when it does not exist.
    static std::uint64_t bytes_below(const std::string& path);

private:
    std::uint64_t set_aside_locked(const Admission* except) const;

    const std::string path_;
    const std::uint64_t max_total_;
    mutable std::mutex mutex_;
    std::int64_t used_ = 0;  // guarded by mutex_
    std::list<Admission*> admitted_;
};

}  // namespace rr::server::record
