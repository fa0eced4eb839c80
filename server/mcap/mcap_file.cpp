#include "server/mcap/mcap_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace rr::mcap {
namespace {

Unexpected io_error(const std::string& what, const std::string& path, int err) {
    return fail(MessageErrorType::IOError, "mcap: " + what + " " + path + ": " + std::strerror(err));
}

}  // namespace

Result<std::unique_ptr<FileSink>> FileSink::create(const std::string& path, bool fsync_on_flush) {
    int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return io_error("cannot create", path, errno);
    return std::unique_ptr<FileSink>(new FileSink(fd, path, fsync_on_flush));
}

std::unique_ptr<FileSink> FileSink::adopt(int fd, std::string path, bool fsync_on_flush) {
    return std::unique_ptr<FileSink>(new FileSink(fd, std::move(path), fsync_on_flush));
}

FileSink::~FileSink() {
    if (fd_ >= 0) ::close(fd_);
}

Result<void> FileSink::write(std::span<const std::byte> bytes) {
    if (fd_ < 0) return fail(MessageErrorType::InvalidState, "mcap: " + path_ + " is closed");
    while (!bytes.empty()) {
        ssize_t n = ::write(fd_, bytes.data(), bytes.size());
        if (n < 0) {
            if (errno == EINTR) continue;
            return io_error("cannot write", path_, errno);
        }
        bytes = bytes.subspan(static_cast<std::size_t>(n));
    }
    return {};
}

Result<void> FileSink::flush() {
    // write() goes straight to the kernel: a killed process loses nothing already written. fsync only
    // matters for power loss.
    if (fsync_ && fd_ >= 0 && ::fsync(fd_) != 0) return io_error("cannot fsync", path_, errno);
    return {};
}

Result<void> FileSink::close() {
    if (fd_ < 0) return {};
    int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) return io_error("cannot close", path_, errno);
    return {};
}

Result<std::unique_ptr<FileSource>> FileSource::open(const std::string& path) {
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return io_error("cannot open", path, errno);
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
        int err = errno;
        ::close(fd);
        return io_error("cannot stat", path, err);
    }
    if (!S_ISREG(st.st_mode)) {
        ::close(fd);
        return fail(MessageErrorType::IOError, "mcap: " + path + " is not a regular file");
    }
    return std::unique_ptr<FileSource>(new FileSource(fd, path, static_cast<std::uint64_t>(st.st_size)));
}

FileSource::~FileSource() {
    if (fd_ >= 0) ::close(fd_);
}

Result<void> FileSource::read_at(std::uint64_t offset, std::span<std::byte> out) {
    if (offset > size_ || out.size() > size_ - offset)
        return fail(MessageErrorType::IOError, "mcap: read past the end of " + path_);
    while (!out.empty()) {
        ssize_t n = ::pread(fd_, out.data(), out.size(), static_cast<off_t>(offset));
        if (n < 0) {
            if (errno == EINTR) continue;
            return io_error("cannot read", path_, errno);
        }
        if (n == 0) return fail(MessageErrorType::IOError, "mcap: " + path_ + " shrank while being read");
        out = out.subspan(static_cast<std::size_t>(n));
        offset += static_cast<std::uint64_t>(n);
    }
    return {};
}

}  // namespace rr::mcap
