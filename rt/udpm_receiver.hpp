// A direct receiver for one LCM udpm bus, read by the caller's own thread: the lockstep hot path
// (sensor frames into rocksteady-fsw, thruster commands into rocksteady-plant) without LCM's
// receive thread. LCM 1.3's udpm provider reads its socket on a thread of its own and wakes the
// application through a pipe: two wake-ups per message; this socket wakes the loop directly.
//
// It receives LCM's small-message packets (magic "LC02", sequence number, NUL-terminated channel,
// payload: what LCM 1.3's lcm_publish sends in one datagram, up to ~64 KB). Fragmented messages
// ("LC03") and malformed packets are counted and dropped: the hot channels carry small messages.
// Publishing stays with LCM (lcm_publish), and other LCM tools on the bus (loggers, lcm-spy) see
// the same traffic. Do not also lcm_subscribe to the same URL in this process: LCM would start its
// receive thread and read every packet too.
#pragma once

#include <cstdint>
#include <string>

namespace rocksteady::rt {

class UdpmReceiver {
 public:
  UdpmReceiver() = default;
  UdpmReceiver(const UdpmReceiver&) = delete;
  UdpmReceiver& operator=(const UdpmReceiver&) = delete;
  ~UdpmReceiver();

  // `url` as LCM's: udpm://GROUP:PORT[?options] (options are LCM's; ignored here). False with
  // error() on a bad URL or a socket error.
  bool open(const std::string& url);
  int fd() const { return fd_; }
  const std::string& error() const { return error_; }

  // One packet, without blocking: 1 and the channel and payload (valid until the next call), 0 when
  // nothing is waiting, -1 on a socket error. A packet that is not an LCM small message is counted
  // in rejected() and skipped.
  int receive(const char** channel, const void** data, int* size);

  std::uint64_t received() const { return received_; }
  std::uint64_t rejected() const { return rejected_; }

 private:
  int fd_{-1};
  std::string error_;
  unsigned char buf_[65536]{};
  std::uint64_t received_{0};
  std::uint64_t rejected_{0};
};

}  // namespace rocksteady::rt
