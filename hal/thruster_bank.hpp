// ThrusterBank: the eight signed thruster channels of the flight core <-> the 16 physical on/off
// thrusters, 4 pods x 4 (SPEC §4). A channel is one opposed pair in one pod: a positive force fires
// its "+" thruster, a negative force its "-" thruster. Which physical thrusters form each channel is
// configuration data, validated once at init. No heap, no exceptions.
#pragma once

#include <array>
#include <cstdint>

#include "gnc/io.hpp"
#include "hal/readings.hpp"
#include "gnc/model/rcs.hpp"
#include "gnc/types.hpp"

namespace rocksteady::hal {

struct ChannelWiring {
  int pod{0};    // 0..3
  int plus{0};   // position in the pod (0..3) of the thruster fired by a positive force
  int minus{1};  // position in the pod of the thruster fired by a negative force
};

struct ThrusterBankConfig {
  std::array<ChannelWiring, gnc::kChannels> channel{};
  double u_max{200.0};     // N, per-thruster force limit (= the channel limit of SPEC §4)
  double min_force{0.0};   // N, a channel with |u| <= min_force leaves both thrusters off
};

// SPEC §4 wiring: channel 2k = pod k tangential pair at positions (0 "+", 1 "-"), channel 2k+1 =
// pod k axial pair at positions (2 "+", 3 "-").
ThrusterBankConfig default_thruster_bank_config(double u_max);

enum class BankConfigError : std::uint8_t {
  kOk = 0,
  kPodOutOfRange,
  kPositionOutOfRange,
  kPlusEqualsMinus,
  kThrusterUsedTwice,      // a physical thruster appears in two channels (or twice in one)
  kPodDisagreesWithLayout, // channel's pod differs from gnc::RcsLayout::channel_pod
  kBadForceLimit,          // u_max not finite/positive, or min_force not in [0, u_max)
};
const char* to_string(BankConfigError e);

struct BankConfigCheck {
  BankConfigError error{BankConfigError::kOk};
  int channel{-1};  // first offending channel (-1 when not channel-specific)
  bool ok() const { return error == BankConfigError::kOk; }
};

// Validates the wiring (each of the 16 thrusters used exactly once, indices in range) and, when
// `layout` is given, that each channel sits in the pod the flight core's RCS layout says it does.
BankConfigCheck validate(const ThrusterBankConfig& config, const gnc::RcsLayout* layout = nullptr);

// What the bank drives: one on/off and force per physical thruster.
struct BankStatus {
  int clamped{0};     // channels whose |u| exceeded u_max (fired at u_max)
  int non_finite{0};  // channels with a NaN/Inf force (left off)
};

// The same mapping for a wiring alone (a port that reports channel forces beside the thrusters).
gnc::Vec8 channel_forces(const ThrusterBankConfig& wiring, const ThrusterOutputs& outputs);

class ThrusterBank {
 public:
  // Installs a validated configuration. On error the bank keeps (or stays in) the all-off state.
  BankConfigCheck configure(const ThrusterBankConfig& config, const gnc::RcsLayout* layout = nullptr);
  bool configured() const { return configured_; }
  const ThrusterBankConfig& config() const { return config_; }

  // Channel forces -> physical thrusters. Every thruster off when the command is disabled or the bank
  // is not configured. The latch valves take the command's valve_open (all open when unconfigured).
  BankStatus command(const gnc::ThrusterCommand& cmd, ThrusterOutputs& out) const;

  // Physical thrusters -> signed channel forces (u_i = F_plus - F_minus); for plants and telemetry.
  gnc::Vec8 channel_forces(const ThrusterOutputs& outputs) const;

 private:
  ThrusterBankConfig config_{};
  bool configured_{false};
};

}  // namespace rocksteady::hal
