// Fixed-capacity event queue (ring). When full, the new event is dropped and counted: the reports
// already waiting are kept (they explain what led here).
#pragma once

#include <array>
#include <cstdint>

#include "fsw/interface.hpp"

namespace rocksteady::fsw {

class EventQueue {
 public:
  static constexpr int kCapacity = 64;

  bool push(const Event& e);
  bool pop(Event& e);
  int size() const { return count_; }
  std::uint32_t dropped() const { return dropped_; }
  void reset_dropped() { dropped_ = 0; }

 private:
  std::array<Event, kCapacity> ring_{};
  int head_{0};
  int count_{0};
  std::uint32_t dropped_{0};
};

}  // namespace rocksteady::fsw
