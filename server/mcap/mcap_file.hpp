// Files as MCAP sinks and sources (core/mcap/mcap_io.hpp), with POSIX calls.
//
// FileSink appends to a new file; flush() hands the written bytes to the kernel and, when asked for,
// fsyncs them (WriterOptions-independent: McapWriter calls flush() after each chunk and at close).
// FileSource reads a file at offsets; its size is the file's size when it was opened (a file still
// being written can be read up to that point).
// Errors: IOError with the path and the system's reason, e.g.
// "mcap: cannot open /var/rec/a.mcap: No such file or directory". Not thread-safe.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "core/mcap/mcap_io.hpp"

namespace rr::mcap {

class FileSink final : public Sink {
public:
    /// Creates (or truncates) `path`. With `fsync_on_flush`, flush() also waits for the disk.
    static Result<std::unique_ptr<FileSink>> create(const std::string& path, bool fsync_on_flush = false);
    /// Takes an open, writable descriptor (the recorder opens its files itself: openat with O_EXCL and
    /// O_NOFOLLOW, server/record/recordings_root.hpp); `path` names it in messages.
    static std::unique_ptr<FileSink> adopt(int fd, std::string path, bool fsync_on_flush = false);
    ~FileSink() override;
    Result<void> write(std::span<const std::byte> bytes) override;
    Result<void> flush() override;
    /// Closes the file descriptor (the destructor does it too, ignoring errors).
    Result<void> close();
    const std::string& path() const noexcept { return path_; }

private:
    FileSink(int fd, std::string path, bool fsync_on_flush) : fd_(fd), path_(std::move(path)), fsync_(fsync_on_flush) {}
    int fd_ = -1;
    std::string path_;
    bool fsync_ = false;
};

class FileSource final : public Source {
public:
    static Result<std::unique_ptr<FileSource>> open(const std::string& path);
    ~FileSource() override;
    std::uint64_t size() const override { return size_; }
    Result<void> read_at(std::uint64_t offset, std::span<std::byte> out) override;
    const std::string& path() const noexcept { return path_; }

private:
    FileSource(int fd, std::string path, std::uint64_t size) : fd_(fd), path_(std::move(path)), size_(size) {}
    int fd_ = -1;
    std::string path_;
    std::uint64_t size_ = 0;
};

}  // namespace rr::mcap
