#include "io/files.hpp"

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <random>
#include <sstream>
#include <unistd.h>

namespace jointid::io {

namespace {

std::string reason(int error_number) {
  return std::strerror(error_number);
}

// A name in the target's directory that no other writer (thread or process) uses.
std::filesystem::path temporary_name(const std::filesystem::path& path, int attempt) {
  static std::atomic<unsigned> counter{0};
  static const unsigned salt = std::random_device{}();
  std::string name = ".";
  name += path.filename().string();
  name += ".tmp." + std::to_string(::getpid()) + "." + std::to_string(salt) + "." +
          std::to_string(counter++) + "." + std::to_string(attempt);
  return path.parent_path() / name;
}

} // namespace

std::string read_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw Error(path.string() + ": is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open for reading: " + reason(errno));
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw Error(path.string() + ": read error");
  return content.str();
}

void write_file_atomically(const std::filesystem::path& path, const std::string& content) {
  if (path.filename().empty())
    throw Error("'" + path.string() + "': expected a file name, got a directory");
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw Error(path.string() + ": is a directory, cannot write a file there");

  // O_EXCL: never reuse a name; 0666 lets the umask decide the permissions as for any new file.
  std::filesystem::path tmp;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    tmp = temporary_name(path, attempt);
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) throw Error(path.string() + ": cannot write: " + reason(errno));

  auto fail = [&](const std::string& what, int error_number) {
    if (fd >= 0) ::close(fd);
    std::filesystem::remove(tmp, ec);
    throw Error(path.string() + ": " + what + ": " + reason(error_number));
  };
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, data, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("write failed", errno);
    }
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) fail("write failed", errno);
  const int closed = ::close(fd);
  fd = -1;
  if (closed != 0) fail("write failed", errno);
  if (::rename(tmp.c_str(), path.c_str()) != 0) fail("cannot replace the file", errno);
}

} // namespace jointid::io
