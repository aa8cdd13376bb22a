#include "core/atomic_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fcntl.h>
#include <unistd.h>

#include "core/errors.h"

namespace lobe {

namespace {

std::string errno_text() { return std::strerror(errno); }

void fsync_directory_of(const std::string& path)
{
    std::filesystem::path dir = std::filesystem::path(path).parent_path();
    if (dir.empty()) dir = ".";
    int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
    if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
    }
}

} // namespace

void write_file_atomic(const std::string& path, std::string_view content)
{
    const std::string tmp = path + ".tmp." + std::to_string(::getpid());
    int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw FileError(path, "cannot create temporary file: " + errno_text());
    std::size_t written = 0;
    while (written < content.size()) {
        ssize_t n = ::write(fd, content.data() + written, content.size() - written);
        if (n < 0) {
            if (errno == EINTR) continue;
            std::string why = errno_text();
            ::close(fd);
            ::unlink(tmp.c_str());
            throw FileError(path, "write failed: " + why);
        }
        written += static_cast<std::size_t>(n);
    }
    if (::fsync(fd) != 0 || ::close(fd) != 0) {
        std::string why = errno_text();
        ::unlink(tmp.c_str());
        throw FileError(path, "flush failed: " + why);
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::string why = errno_text();
        ::unlink(tmp.c_str());
        throw FileError(path, "cannot replace file: " + why);
    }
    fsync_directory_of(path);
}

std::string read_file_limited(const std::string& path, std::size_t max_bytes)
{
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw FileError(path, "no such file");
    auto size = std::filesystem::file_size(path, ec);
    if (ec) throw FileError(path, "cannot read size: " + ec.message());
    if (size > max_bytes)
        throw FileError(path, "file too large (" + std::to_string(size) + " bytes, limit " +
                                  std::to_string(max_bytes) + ")");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw FileError(path, "cannot open for reading");
    std::string data(static_cast<std::size_t>(size), '\0');
    in.read(data.data(), static_cast<std::streamsize>(size));
    data.resize(static_cast<std::size_t>(in.gcount()));
    return data;
}

} // namespace lobe
