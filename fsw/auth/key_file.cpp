#include "fsw/auth/key_file.hpp"

#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

namespace rocksteady::fsw::auth {

namespace {

std::string sys_error(const std::string& path, const char* what) {
  return path + ": " + what + ": " + std::strerror(errno);
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Reads a whole (small) file from an open descriptor.
bool read_all(int fd, std::string& out) {
  char buf[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      sodium_memzero(buf, sizeof buf);
      return false;
    }
    if (n == 0) break;
    out.append(buf, static_cast<std::size_t>(n));
    if (out.size() > 65536) break;
  }
  sodium_memzero(buf, sizeof buf);
  return true;
}

void wipe(std::string& s) {
  if (!s.empty()) sodium_memzero(&s[0], s.size());
  s.clear();
}

}  // namespace

std::string load_key_file(const std::string& path, KeySet& out) {
  out = KeySet{};
  if (sodium_init() < 0) return "libsodium could not be initialised";
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return sys_error(path, "cannot open the key file");
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const std::string e = sys_error(path, "cannot stat the key file");
    ::close(fd);
    return e;
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    return path + ": not a regular file";
  }
  if (st.st_uid != ::geteuid()) {
    ::close(fd);
    return path + ": the key file is not owned by the user running this program";
  }
  if ((st.st_mode & 077) != 0) {
    ::close(fd);
    char mode[16];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    return path + ": permissions " + mode +
           " are too open: the key file must be readable by its owner only (chmod 600)";
  }
  std::string text;
  const bool ok = read_all(fd, text);
  ::close(fd);
  if (!ok) return sys_error(path, "cannot read the key file");

  std::string error;
  std::size_t pos = 0;
  int line_no = 0;
  while (pos < text.size() && error.empty()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    ++line_no;
    const char* p = text.data() + pos;
    const char* e = text.data() + end;
    pos = end + 1;
    while (p < e && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
    if (p == e || *p == '#') continue;
    const std::string where = path + ": line " + std::to_string(line_no) + ": ";
    // id
    std::int64_t id = 0;
    const char* q = p;
    while (q < e && *q >= '0' && *q <= '9') {
      id = id * 10 + (*q - '0');
      if (id > 2147483647) break;
      ++q;
    }
    if (q == p || id <= 0 || id > 2147483647 || q == e || (*q != ' ' && *q != '\t')) {
      error = where + "expected '<key id> <64 hex digits>' with a positive key id";
      break;
    }
    while (q < e && (*q == ' ' || *q == '\t')) ++q;
    const char* h = q;
    while (q < e && hex_value(*q) >= 0) ++q;
    const char* h_end = q;
    while (q < e && (*q == ' ' || *q == '\t' || *q == '\r')) ++q;
    if (h_end - h != 2 * kKeyBytes || q != e) {
      error = where + "the key must be exactly 64 hex digits";
      break;
    }
    if (out.count >= kMaxKeys) {
      error = where + "too many keys (at most " + std::to_string(kMaxKeys) + ")";
      break;
    }
    if (out.find(static_cast<std::int32_t>(id)) != nullptr) {
      error = where + "duplicate key id " + std::to_string(id);
      break;
    }
    KeyEntry& k = out.keys[static_cast<std::size_t>(out.count)];
    k.id = static_cast<std::int32_t>(id);
    for (int i = 0; i < kKeyBytes; ++i) {
      k.key[static_cast<std::size_t>(i)] =
          static_cast<std::uint8_t>(hex_value(h[2 * i]) * 16 + hex_value(h[2 * i + 1]));
    }
    ++out.count;
  }
  wipe(text);
  if (error.empty() && out.count == 0) error = path + ": no key in the key file";
  if (!error.empty()) {
    sodium_memzero(&out, sizeof out);
    out = KeySet{};
  }
  return error;
}

std::string generate_key_file(const std::string& path, int count, std::int32_t first_id) {
  if (sodium_init() < 0) return "libsodium could not be initialised";
  if (count < 1 || count > kMaxKeys) return "key count must be 1.." + std::to_string(kMaxKeys);
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) return sys_error(path, "cannot create the key file");
  std::string text =
      "# Rocksteady command keys: <key id> <64 hex digits>. Secret: keep mode 0600.\n"
      "# The flight starts with the lowest id; KEY_ROTATE moves to a higher one.\n";
  for (int i = 0; i < count; ++i) {
    unsigned char key[kKeyBytes];
    crypto_auth_hmacsha256_keygen(key);
    char hex[2 * kKeyBytes + 1];
    sodium_bin2hex(hex, sizeof hex, key, sizeof key);
    text += std::to_string(first_id + i) + " " + hex + "\n";
    sodium_memzero(key, sizeof key);
    sodium_memzero(hex, sizeof hex);
  }
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()) &&
                  ::fsync(fd) == 0;
  wipe(text);
  ::close(fd);
  if (!ok) return sys_error(path, "cannot write the key file");
  return "";
}

std::string load_state_file(const std::string& path, SecurityConfig& config, bool& missing) {
  missing = false;
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (f == nullptr) {
    if (errno == ENOENT) {
      missing = true;
      return "";
    }
    return sys_error(path, "cannot open the state file");
  }
  char line[256];
  int line_no = 0;
  std::string error;
  bool header = false;
  config.restored = 0;
  while (std::fgets(line, sizeof line, f) != nullptr) {
    ++line_no;
    const std::string where = path + ": line " + std::to_string(line_no) + ": ";
    int version = 0;
    long long id = 0, counter = 0;
    char extra = 0;
    if (!header) {
      if (std::sscanf(line, "rocksteady-auth-state %d %c", &version, &extra) != 1 || version != 1) {
        error = where + "not a Rocksteady state file (expected 'rocksteady-auth-state 1')";
        break;
      }
      header = true;
    } else if (std::sscanf(line, "active %lld %c", &id, &extra) == 1) {
      if (id <= 0 || id > 2147483647) {
        error = where + "bad active key id";
        break;
      }
      config.active_key_id = static_cast<std::int32_t>(id);
    } else if (std::sscanf(line, "counter %lld %lld %c", &id, &counter, &extra) == 2) {
      if (id <= 0 || id > 2147483647 || counter < 0 || config.restored >= kMaxKeys) {
        error = where + "bad counter line";
        break;
      }
      config.restored_key[static_cast<std::size_t>(config.restored)] = static_cast<std::int32_t>(id);
      config.restored_counter[static_cast<std::size_t>(config.restored)] = counter;
      ++config.restored;
    } else {
      error = where + "expected 'active <id>' or 'counter <id> <highest>'";
      break;
    }
  }
  std::fclose(f);
  if (error.empty() && !header) error = path + ": empty state file";
  return error;
}

std::string write_state_file(const std::string& path, const SecurityState& state) {
  char text[1024];
  int n = std::snprintf(text, sizeof text, "rocksteady-auth-state 1\nactive %" PRId32 "\n",
                        state.active_key_id);
  for (int i = 0; i < state.count && i < kMaxKeys; ++i) {
    n += std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n),
                       "counter %" PRId32 " %" PRId64 "\n", state.key_id[static_cast<std::size_t>(i)],
                       state.highest[static_cast<std::size_t>(i)]);
  }
  const std::string tmp = path + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) return sys_error(tmp, "cannot write the state file");
  const bool ok = ::write(fd, text, static_cast<std::size_t>(n)) == n && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok) return sys_error(tmp, "cannot write the state file");
  if (std::rename(tmp.c_str(), path.c_str()) != 0) return sys_error(path, "cannot replace");
  return "";
}

}  // namespace rocksteady::fsw::auth
