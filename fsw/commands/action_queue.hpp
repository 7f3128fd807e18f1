// Accepted commands waiting for the tick boundary: a fixed ring, in submission order. The queue
// also answers "what will the state be once everything queued has been applied" (the projected
// mode, law and trajectory), which is what a new command is checked against.
#pragma once

#include <array>
#include <cstdint>

#include "gnc/gnc.hpp"

namespace rocksteady::fsw {

enum class ActionKind : std::uint8_t {
  kMode,
  kLaw,
  kTarget,
  kActivateParams,
  kLoadTrajectory,
  kResetCounters,
  kRotateKey,  // key_id becomes the active command key (fsw/auth)
  kFaultDeclare,    // thruster, fault (kNone: clear; thruster -1: every thruster)
  kValve,           // pod, open
  kIsolation,       // inhibit automatic isolation (flag)
};

struct Action {
  ActionKind kind{ActionKind::kMode};
  gnc::Mode mode{gnc::Mode::kIdle};
  gnc::LawId law{gnc::LawId::kNtcl};
  gnc::Vec3 target{gnc::Vec3::Zero()};
  std::int32_t upload_id{0};
  std::int32_t key_id{0};
  std::int8_t thruster{-1};  // kFaultDeclare; kValve: the pod
  gnc::FaultKind fault{gnc::FaultKind::kNone};
  bool flag{false};          // kValve: open; kIsolation: inhibited
  double factor{1.0};        // kFaultDeclare of a degraded thruster: its strength factor
};

class ActionQueue {
 public:
  static constexpr int kCapacity = 16;

  void clear() {
    head_ = 0;
    count_ = 0;
  }
  bool has_room(int n) const { return count_ + n <= kCapacity; }
  void push(const Action& a) {
    ring_[(head_ + count_) % kCapacity] = a;
    ++count_;
  }
  const Action& front() const { return ring_[head_]; }
  void pop() {
    head_ = (head_ + 1) % kCapacity;
    --count_;
  }
  int size() const { return count_; }
  bool empty() const { return count_ == 0; }

  // The last queued mode (law), or `current` when none is queued.
  gnc::Mode projected_mode(gnc::Mode current) const;
  gnc::LawId projected_law(gnc::LawId current) const;
  bool has(ActionKind kind) const;

 private:
  std::array<Action, kCapacity> ring_{};
  int head_{0};
  int count_{0};
};

inline gnc::Mode ActionQueue::projected_mode(gnc::Mode current) const {
  for (int i = 0; i < count_; ++i) {
    const Action& a = ring_[(head_ + i) % kCapacity];
    if (a.kind == ActionKind::kMode) current = a.mode;
  }
  return current;
}

inline gnc::LawId ActionQueue::projected_law(gnc::LawId current) const {
  for (int i = 0; i < count_; ++i) {
    const Action& a = ring_[(head_ + i) % kCapacity];
    if (a.kind == ActionKind::kLaw) current = a.law;
  }
  return current;
}

inline bool ActionQueue::has(ActionKind kind) const {
  for (int i = 0; i < count_; ++i) {
    if (ring_[(head_ + i) % kCapacity].kind == kind) return true;
  }
  return false;
}

}  // namespace rocksteady::fsw
