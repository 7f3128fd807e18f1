#include "fsw/events/event_queue.hpp"

namespace rocksteady::fsw {

bool EventQueue::push(const Event& e) {
  if (count_ >= kCapacity) {
    ++dropped_;
    return false;
  }
  ring_[(head_ + count_) % kCapacity] = e;
  ++count_;
  return true;
}

bool EventQueue::pop(Event& e) {
  if (count_ == 0) return false;
  e = ring_[head_];
  head_ = (head_ + 1) % kCapacity;
  --count_;
  return true;
}

}  // namespace rocksteady::fsw
