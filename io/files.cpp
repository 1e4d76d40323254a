#include "io/files.hpp"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <mutex>
#include <random>
#include <sstream>
#include <sys/stat.h>
#include <sys/syscall.h>
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

// ---------------------------------------------------------------------------------------------
// Temporary names in progress, readable from a signal handler: fixed slots, no allocation.

constexpr int max_in_flight = 256;
constexpr std::size_t max_path = 4096;

enum SlotState : int { free_slot = 0, filling = 1, registered = 2 };

struct Slot {
  std::atomic<int> state{free_slot};
  bool directory = false;
  char path[max_path] = {};
};

Slot in_flight[max_in_flight];
std::atomic<int> interrupt_signal{0}; // the signal that arrived, 0 if none
std::atomic<int> commits{0};          // CommitSections alive

// Linux's getdents64 record (the libc wrapper, readdir, may allocate: not for a handler).
struct DirectoryEntry {
  unsigned long long inode;
  long long offset;
  unsigned short length;
  unsigned char type;
  char name[1];
};

// Removes `name` (relative to the directory `parent`) and, if it is a directory, everything
// in it; only async-signal-safe calls.
void remove_tree(int parent, const char* name, int depth) {
  if (::unlinkat(parent, name, 0) == 0 || errno == ENOENT) return;
  if (depth < 16) {
    const int fd = ::openat(parent, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    if (fd >= 0) {
      // Entries removed while listing may shift the listing: list again until it is empty.
      for (int pass = 0; pass < 8; ++pass) {
        bool found = false;
        ::lseek(fd, 0, SEEK_SET);
        alignas(8) char buffer[2048];
        for (;;) {
          const long n = ::syscall(SYS_getdents64, fd, buffer, sizeof buffer);
          if (n <= 0) break;
          for (long at = 0; at < n;) {
            const auto* entry = reinterpret_cast<const DirectoryEntry*>(buffer + at);
            at += entry->length;
            const char* child = entry->name;
            if (child[0] == '.' && (child[1] == '\0' || (child[1] == '.' && child[2] == '\0')))
              continue;
            found = true;
            remove_tree(fd, child, depth + 1);
          }
        }
        if (!found) break;
      }
      ::close(fd);
    }
  }
  ::unlinkat(parent, name, AT_REMOVEDIR);
}

void remove_in_flight() {
  for (Slot& slot : in_flight)
    if (slot.state.load() == registered) {
      if (slot.directory)
        remove_tree(AT_FDCWD, slot.path, 0);
      else
        ::unlink(slot.path);
    }
}

[[noreturn]] void exit_interrupted(int signal) {
  remove_in_flight();
  ::_exit(128 + signal);
}

extern "C" void on_interrupt(int signal) {
  const int saved_errno = errno;
  interrupt_signal.store(signal);
  if (commits.load() == 0) exit_interrupted(signal);
  errno = saved_errno; // a CommitSection is renaming outputs into place: it exits when done
}

// ---------------------------------------------------------------------------------------------
// Inputs of this run (protect_inputs), by device and inode: a path given twice, through a
// link or with another spelling is the same file.

struct Inputs {
  std::mutex mutex;
  bool enabled = false;
  std::vector<std::pair<dev_t, ino_t>> files;
};

Inputs& inputs() {
  static Inputs instance;
  return instance;
}

void remember_input(const std::filesystem::path& path) {
  Inputs& in = inputs();
  const std::lock_guard lock(in.mutex);
  struct stat s {};
  if (!in.enabled || ::stat(path.c_str(), &s) != 0) return;
  in.files.emplace_back(s.st_dev, s.st_ino);
}

} // namespace

std::string read_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw Error(path.string() + ": is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open for reading: " + reason(errno));
  remember_input(path);
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw Error(path.string() + ": read error");
  return content.str();
}

void protect_inputs() {
  Inputs& in = inputs();
  const std::lock_guard lock(in.mutex);
  in.enabled = true;
}

void check_not_an_input(const std::filesystem::path& path) {
  Inputs& in = inputs();
  const std::lock_guard lock(in.mutex);
  struct stat s {};
  if (!in.enabled || ::stat(path.c_str(), &s) != 0) return;
  for (const auto& [device, inode] : in.files)
    if (device == s.st_dev && inode == s.st_ino)
      throw Error(path.string() +
                  ": is an input of this run; refusing to write over it (choose another output)");
}

// ---------------------------------------------------------------------------------------------

InFlight::InFlight(const std::filesystem::path& path, Kind kind) {
  std::error_code ec;
  const std::string absolute = std::filesystem::absolute(path, ec).string();
  if (ec || absolute.size() >= max_path) return; // not tracked
  for (int i = 0; i < max_in_flight; ++i) {
    int expected = free_slot;
    if (!in_flight[i].state.compare_exchange_strong(expected, filling)) continue;
    in_flight[i].directory = kind == Kind::directory;
    std::memcpy(in_flight[i].path, absolute.c_str(), absolute.size() + 1);
    in_flight[i].state.store(registered);
    slot_ = i;
    return;
  }
}

InFlight::~InFlight() {
  if (slot_ >= 0) in_flight[slot_].state.store(free_slot);
}

CommitSection::CommitSection() {
  // Paired with on_interrupt: of "count this section" and "note the signal", each side does
  // its store before its load, so at least one of them sees the other and exits.
  if (commits.fetch_add(1) == 0)
    if (const int signal = interrupt_signal.load()) exit_interrupted(signal);
}

CommitSection::~CommitSection() {
  if (commits.fetch_sub(1) == 1)
    if (const int signal = interrupt_signal.load()) exit_interrupted(signal);
}

void install_interrupt_cleanup() {
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigfillset(&action.sa_mask); // one handler at a time
  action.sa_flags = SA_RESTART;
  for (const int signal : {SIGINT, SIGTERM, SIGHUP})
    ::sigaction(signal, &action, nullptr);
}

// ---------------------------------------------------------------------------------------------

OutputFiles::~OutputFiles() {
  std::error_code ec;
  for (auto& s : staged_)
    if (!s.temporary.empty()) std::filesystem::remove(s.temporary, ec);
}

void OutputFiles::add(const std::filesystem::path& path, const std::string& content) {
  if (path.filename().empty())
    throw Error("'" + path.string() + "': expected a file name, got a directory");
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw Error(path.string() + ": is a directory, cannot write a file there");
  check_not_an_input(path);

  // O_EXCL: never reuse a name; 0666 lets the umask decide the permissions as for any new file.
  // The name is registered before the file exists, so that an interrupt never misses it.
  std::filesystem::path tmp;
  std::unique_ptr<InFlight> registration;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    tmp = temporary_name(path, attempt);
    registration = std::make_unique<InFlight>(tmp, InFlight::Kind::file);
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
  staged_.push_back({path, tmp, std::move(registration)});
}

void OutputFiles::commit() {
  const CommitSection section;
  for (auto& s : staged_) {
    if (::rename(s.temporary.c_str(), s.target.c_str()) != 0)
      throw Error(s.target.string() + ": cannot replace the file: " + reason(errno));
    s.temporary.clear();
    s.registration.reset();
  }
  staged_.clear();
}

void write_file_atomically(const std::filesystem::path& path, const std::string& content) {
  OutputFiles output;
  output.add(path, content);
  output.commit();
}

} // namespace jointid::io
