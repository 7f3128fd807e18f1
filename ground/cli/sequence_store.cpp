#include "ground/cli/sequence_store.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>

namespace rocksteady::ground::cli {

namespace {

std::runtime_error error(const std::string& path, const std::string& what) {
  return std::runtime_error("sequence state " + path + ": " + what + ": " + std::strerror(errno));
}

// The file's content: the last number in decimal; anything else reads as 0.
std::int64_t parse(const std::string& text) {
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  return end != text.c_str() && v > 0 ? static_cast<std::int64_t>(v) : 0;
}

std::string read_all(int fd) {
  std::string text;
  char buf[64];
  if (lseek(fd, 0, SEEK_SET) < 0) return text;
  for (;;) {
    const ssize_t n = read(fd, buf, sizeof buf);
    if (n <= 0) break;
    text.append(buf, static_cast<std::size_t>(n));
  }
  return text;
}

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) close(fd_);  // also releases the flock
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

std::string default_state_dir() {
  const char* xdg = std::getenv("XDG_STATE_HOME");
  if (xdg != nullptr && xdg[0] == '/') return std::string(xdg) + "/rocksteady";
  const char* home = std::getenv("HOME");
  if (home != nullptr && home[0] != '\0') return std::string(home) + "/.local/state/rocksteady";
  return "";
}

std::string sequence_file(const std::string& dir, std::int32_t sender_id) {
  return dir + "/ground-seq-" + std::to_string(sender_id);
}

std::int64_t SequenceStore::next(std::int64_t at_least) {
  const std::filesystem::path p(path_);
  if (p.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(p.parent_path(), ec);
    if (ec) throw std::runtime_error("sequence state " + path_ + ": " + ec.message());
  }
  const Fd fd(open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644));
  if (fd.get() < 0) throw error(path_, "open");
  if (flock(fd.get(), LOCK_EX) != 0) throw error(path_, "lock");
  const std::int64_t last_seq = parse(read_all(fd.get()));
  const std::int64_t seq = last_seq + 1 > at_least ? last_seq + 1 : at_least;
  const std::string text = std::to_string(seq) + "\n";
  if (ftruncate(fd.get(), 0) != 0 || lseek(fd.get(), 0, SEEK_SET) < 0 ||
      write(fd.get(), text.data(), text.size()) != static_cast<ssize_t>(text.size()) ||
      fsync(fd.get()) != 0) {
    throw error(path_, "write");
  }
  return seq;
}

std::int64_t SequenceStore::last() const {
  const Fd fd(open(path_.c_str(), O_RDONLY | O_CLOEXEC));
  if (fd.get() < 0) return 0;
  if (flock(fd.get(), LOCK_SH) != 0) return 0;
  return parse(read_all(fd.get()));
}

}  // namespace rocksteady::ground::cli
