#include "rt/udpm_receiver.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace rocksteady::rt {

namespace {
constexpr std::uint32_t kMagicShort = 0x4c433032;  // "LC02"
constexpr int kHeaderBytes = 8;                    // magic, sequence number
constexpr int kMaxChannel = 63;                    // LCM_MAX_CHANNEL_NAME_LENGTH
}  // namespace

UdpmReceiver::~UdpmReceiver() {
  if (fd_ >= 0) close(fd_);
}

bool UdpmReceiver::open(const std::string& url) {
  const std::string prefix = "udpm://";
  if (url.rfind(prefix, 0) != 0) {
    error_ = "not a udpm:// URL: " + url;
    return false;
  }
  const std::string rest = url.substr(prefix.size(), url.find('?') - prefix.size());
  const std::size_t colon = rest.find(':');
  const std::string group = rest.substr(0, colon);
  int port = 7667;
  if (colon != std::string::npos) {
    char* end = nullptr;
    const long p = std::strtol(rest.c_str() + colon + 1, &end, 10);
    if (end == rest.c_str() + colon + 1 || p <= 0 || p > 65535) {
      error_ = "bad port in " + url;
      return false;
    }
    port = static_cast<int>(p);
  }
  in_addr mc{};
  if (inet_aton(group.c_str(), &mc) == 0) {
    error_ = "bad multicast group in " + url;
    return false;
  }
  fd_ = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    error_ = std::string("socket: ") + std::strerror(errno);
    return false;
  }
  const int one = 1;
  setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);  // as LCM: several readers per port
  const int rcvbuf = 2 * 1024 * 1024;
  setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_ANY);
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  if (bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    error_ = std::string("bind: ") + std::strerror(errno);
    return false;
  }
  ip_mreq mreq{};
  mreq.imr_multiaddr = mc;
  mreq.imr_interface.s_addr = htonl(INADDR_ANY);
  if (setsockopt(fd_, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) != 0) {
    error_ = std::string("IP_ADD_MEMBERSHIP: ") + std::strerror(errno);
    return false;
  }
  return true;
}

int UdpmReceiver::receive(const char** channel, const void** data, int* size) {
  for (;;) {
    const ssize_t n = recv(fd_, buf_, sizeof buf_ - 1, 0);
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return 0;
      if (errno == EINTR) continue;
      return -1;
    }
    std::uint32_t magic = 0;
    if (n >= kHeaderBytes) {
      std::memcpy(&magic, buf_, 4);
      magic = ntohl(magic);
    }
    if (magic != kMagicShort) {
      ++rejected_;  // too short, fragmented (LC03) or not LCM
      continue;
    }
    buf_[n] = 0;
    const char* ch = reinterpret_cast<const char*>(buf_ + kHeaderBytes);
    const std::size_t len = strnlen(ch, static_cast<std::size_t>(n - kHeaderBytes));
    if (len == 0 || len > kMaxChannel || kHeaderBytes + static_cast<ssize_t>(len) + 1 > n) {
      ++rejected_;
      continue;
    }
    ++received_;
    *channel = ch;
    *data = buf_ + kHeaderBytes + len + 1;
    *size = static_cast<int>(n - kHeaderBytes - static_cast<ssize_t>(len) - 1);
    return 1;
  }
}

}  // namespace rocksteady::rt
