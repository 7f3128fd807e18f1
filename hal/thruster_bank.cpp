#include "hal/thruster_bank.hpp"

#include <cmath>

namespace rocksteady::hal {

ThrusterBankConfig default_thruster_bank_config(double u_max) {
  ThrusterBankConfig c{};
  for (int k = 0; k < gnc::kPods; ++k) {
    c.channel[static_cast<std::size_t>(2 * k)] = ChannelWiring{k, 0, 1};      // tangential pair
    c.channel[static_cast<std::size_t>(2 * k + 1)] = ChannelWiring{k, 2, 3};  // axial pair
  }
  c.u_max = u_max;
  c.min_force = 0.0;
  return c;
}

const char* to_string(BankConfigError e) {
  switch (e) {
    case BankConfigError::kOk: return "ok";
    case BankConfigError::kPodOutOfRange: return "pod out of range";
    case BankConfigError::kPositionOutOfRange: return "thruster position out of range";
    case BankConfigError::kPlusEqualsMinus: return "plus and minus thrusters are the same";
    case BankConfigError::kThrusterUsedTwice: return "physical thruster used twice";
    case BankConfigError::kPodDisagreesWithLayout: return "channel pod disagrees with the RCS layout";
    case BankConfigError::kBadForceLimit: return "bad force limit";
  }
  return "unknown";
}

BankConfigCheck validate(const ThrusterBankConfig& config, const gnc::RcsLayout* layout) {
  if (!std::isfinite(config.u_max) || config.u_max <= 0.0 || !std::isfinite(config.min_force) ||
      config.min_force < 0.0 || config.min_force >= config.u_max) {
    return {BankConfigError::kBadForceLimit, -1};
  }
  std::array<bool, kThrusters> used{};
  for (int i = 0; i < gnc::kChannels; ++i) {
    const ChannelWiring& w = config.channel[static_cast<std::size_t>(i)];
    if (w.pod < 0 || w.pod >= gnc::kPods) return {BankConfigError::kPodOutOfRange, i};
    if (w.plus < 0 || w.plus >= kThrustersPerPod || w.minus < 0 || w.minus >= kThrustersPerPod) {
      return {BankConfigError::kPositionOutOfRange, i};
    }
    if (w.plus == w.minus) return {BankConfigError::kPlusEqualsMinus, i};
    for (const int pos : {w.plus, w.minus}) {
      const auto t = static_cast<std::size_t>(thruster_index(w.pod, pos));
      if (used[t]) return {BankConfigError::kThrusterUsedTwice, i};
      used[t] = true;
    }
    if (layout != nullptr && layout->channel_pod[static_cast<std::size_t>(i)] != w.pod) {
      return {BankConfigError::kPodDisagreesWithLayout, i};
    }
  }
  // 8 channels x 2 distinct, never repeated thrusters = all 16 used exactly once.
  return {};
}

BankConfigCheck ThrusterBank::configure(const ThrusterBankConfig& config,
                                        const gnc::RcsLayout* layout) {
  const BankConfigCheck check = validate(config, layout);
  if (check.ok()) {
    config_ = config;
    configured_ = true;
  }
  return check;
}

BankStatus ThrusterBank::command(const gnc::ThrusterCommand& cmd, ThrusterOutputs& out) const {
  out = ThrusterOutputs{};
  BankStatus status{};
  if (!configured_) return status;
  // The latch valves follow their own commands, whether the thrusters are enabled or not.
  out.valve_open = cmd.valve_open;
  if (!cmd.enabled) return status;
  out.enabled = true;
  for (int i = 0; i < gnc::kChannels; ++i) {
    const double u = cmd.force(i);
    if (!std::isfinite(u)) {
      ++status.non_finite;
      continue;
    }
    double magnitude = std::fabs(u);
    if (magnitude <= config_.min_force) continue;
    if (magnitude > config_.u_max) {
      magnitude = config_.u_max;
      ++status.clamped;
    }
    const ChannelWiring& w = config_.channel[static_cast<std::size_t>(i)];
    const auto t = static_cast<std::size_t>(thruster_index(w.pod, u > 0.0 ? w.plus : w.minus));
    out.on[t] = true;
    out.force[t] = magnitude;
  }
  return status;
}

gnc::Vec8 ThrusterBank::channel_forces(const ThrusterOutputs& outputs) const {
  if (!configured_) return gnc::Vec8::Zero();
  return hal::channel_forces(config_, outputs);
}

gnc::Vec8 channel_forces(const ThrusterBankConfig& wiring, const ThrusterOutputs& outputs) {
  gnc::Vec8 u = gnc::Vec8::Zero();
  if (!outputs.enabled) return u;
  for (int i = 0; i < gnc::kChannels; ++i) {
    const ChannelWiring& w = wiring.channel[static_cast<std::size_t>(i)];
    const auto p = static_cast<std::size_t>(thruster_index(w.pod, w.plus));
    const auto m = static_cast<std::size_t>(thruster_index(w.pod, w.minus));
    const double fp = outputs.on[p] ? outputs.force[p] : 0.0;
    const double fm = outputs.on[m] ? outputs.force[m] : 0.0;
    u(i) = fp - fm;
  }
  return u;
}

}  // namespace rocksteady::hal
