// A time-tagged table of desired body rates omega_d(t) and their derivatives, produced on the ground
// by the fuel-optimal planner (Eq. 44) and consumed on board by the TRACK reference (Eqs. 45-48).
#pragma once

#include <array>
#include <cstdint>

#include "gnc/types.hpp"

namespace rocksteady::gnc {

// [Rocksteady choice] fixed capacity per table (the flight core holds two: trajectory_buffers.hpp).
// 1024 samples = 512 Hermite-Simpson nodes: a plan of up to ~12 800 s at the planner's uniform grid
// (a node every 25 s, what the open-loop check needs while the body turns in ~170 s). Each table is
// 57 352 bytes; the wire format (trajectory_chunk_t.MAX_TABLE_SAMPLES) carries the same limit.
inline constexpr int kMaxTrajectorySamples = 1024;

struct TrajectorySample {
  double t{0.0};  // s since the start of the plan
  Vec3 omega_d{Vec3::Zero()};      // rad/s
  Vec3 omega_d_dot{Vec3::Zero()};  // rad/s^2
};

struct TrajectoryTable {
  int count{0};
  std::uint32_t checksum{0};  // CRC-32 over the samples (see trajectory_checksum)
  std::array<TrajectorySample, kMaxTrajectorySamples> samples{};
};

enum class TrajectoryError : std::uint8_t {
  kOk = 0,
  kTooFewSamples,
  kTooManySamples,
  kNonFinite,
  kTimeNotMonotonic,
  kRateAboveBound,
  kBadChecksum,
  kNotAtRestAtEnd,
  kBusyTracking,  // TRACK is following the loaded table: it cannot be replaced now
};
const char* to_string(TrajectoryError e);

// CRC-32 (IEEE 802.3) of the little-endian IEEE-754 bytes of t, omega_d, omega_d_dot of each sample.
std::uint32_t trajectory_checksum(const TrajectoryTable& table);
// Checks count, finiteness, strictly increasing time starting at 0, |omega_d| <= eps_trans, checksum.
TrajectoryError validate_trajectory(const TrajectoryTable& table, double eps_trans);

// Cubic Hermite interpolation of omega_d and its exact derivative at time t (clamped to the table;
// after the end omega_d = last sample and omega_d_dot = 0).
struct TrajectoryPoint {
  Vec3 omega_d;
  Vec3 omega_d_dot;
};
TrajectoryPoint interpolate(const TrajectoryTable& table, double t);

}  // namespace rocksteady::gnc
