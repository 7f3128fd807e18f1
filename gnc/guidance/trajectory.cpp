#include "gnc/guidance/trajectory.hpp"

#include <cmath>
#include <cstring>

namespace rocksteady::gnc {

const char* to_string(TrajectoryError e) {
  switch (e) {
    case TrajectoryError::kOk: return "ok";
    case TrajectoryError::kTooFewSamples: return "fewer than 2 samples";
    case TrajectoryError::kTooManySamples: return "more samples than the on-board table holds";
    case TrajectoryError::kNonFinite: return "non-finite value";
    case TrajectoryError::kTimeNotMonotonic: return "time tags not strictly increasing from 0";
    case TrajectoryError::kRateAboveBound: return "omega_d above eps_trans";
    case TrajectoryError::kBadChecksum: return "checksum mismatch";
    case TrajectoryError::kNotAtRestAtEnd: return "omega_d does not end at rest";
    case TrajectoryError::kBusyTracking: return "TRACK is active: leave TRACK before replacing";
  }
  return "?";
}

namespace {

std::uint32_t crc_update(std::uint32_t crc, double v) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  for (int byte = 0; byte < 8; ++byte) {
    crc ^= static_cast<std::uint32_t>((bits >> (8 * byte)) & 0xFFu);
    for (int k = 0; k < 8; ++k) {
      crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
  }
  return crc;
}

}  // namespace

std::uint32_t trajectory_checksum(const TrajectoryTable& table) {
  std::uint32_t crc = 0xFFFFFFFFu;
  const int n = table.count < 0 ? 0 : (table.count > kMaxTrajectorySamples ? kMaxTrajectorySamples
                                                                            : table.count);
  for (int i = 0; i < n; ++i) {
    const TrajectorySample& s = table.samples[i];
    crc = crc_update(crc, s.t);
    for (int j = 0; j < 3; ++j) crc = crc_update(crc, s.omega_d[j]);
    for (int j = 0; j < 3; ++j) crc = crc_update(crc, s.omega_d_dot[j]);
  }
  return ~crc;
}

TrajectoryError validate_trajectory(const TrajectoryTable& table, double eps_trans) {
  if (table.count < 2) return TrajectoryError::kTooFewSamples;
  if (table.count > kMaxTrajectorySamples) return TrajectoryError::kTooManySamples;
  for (int i = 0; i < table.count; ++i) {
    const TrajectorySample& s = table.samples[i];
    if (!std::isfinite(s.t) || !s.omega_d.allFinite() || !s.omega_d_dot.allFinite()) {
      return TrajectoryError::kNonFinite;
    }
    if ((i == 0 && s.t != 0.0) || (i > 0 && !(s.t > table.samples[i - 1].t))) {
      return TrajectoryError::kTimeNotMonotonic;
    }
    if (s.omega_d.norm() > eps_trans * (1.0 + 1e-9)) return TrajectoryError::kRateAboveBound;
  }
  // Eq. (43): omega_d(t_final) = 0. [Rocksteady choice] tolerance 1e-6 rad/s.
  if (table.samples[table.count - 1].omega_d.norm() > 1e-6) return TrajectoryError::kNotAtRestAtEnd;
  if (trajectory_checksum(table) != table.checksum) return TrajectoryError::kBadChecksum;
  return TrajectoryError::kOk;
}

TrajectoryPoint interpolate(const TrajectoryTable& table, double t) {
  TrajectoryPoint p{Vec3::Zero(), Vec3::Zero()};
  if (table.count <= 0) return p;
  const TrajectorySample& first = table.samples[0];
  const TrajectorySample& last = table.samples[table.count - 1];
  if (t <= first.t) {
    p.omega_d = first.omega_d;
    p.omega_d_dot = first.omega_d_dot;
    return p;
  }
  if (t >= last.t) {
    p.omega_d = last.omega_d;  // after the plan: hold the last value, no acceleration
    return p;
  }
  int lo = 0;
  int hi = table.count - 1;
  while (hi - lo > 1) {  // binary search: samples[lo].t <= t < samples[hi].t
    const int mid = (lo + hi) / 2;
    if (table.samples[mid].t <= t) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  const TrajectorySample& a = table.samples[lo];
  const TrajectorySample& b = table.samples[hi];
  const double h = b.t - a.t;
  const double s = (t - a.t) / h;
  const double s2 = s * s;
  const double s3 = s2 * s;
  // Cubic Hermite basis and derivatives: omega_d and omega_d_dot are consistent (C1).
  const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2,
               h11 = s3 - s2;
  const double d00 = 6 * s2 - 6 * s, d10 = 3 * s2 - 4 * s + 1, d01 = -6 * s2 + 6 * s,
               d11 = 3 * s2 - 2 * s;
  p.omega_d = h00 * a.omega_d + h10 * h * a.omega_d_dot + h01 * b.omega_d + h11 * h * b.omega_d_dot;
  p.omega_d_dot =
      (d00 * a.omega_d + d10 * h * a.omega_d_dot + d01 * b.omega_d + d11 * h * b.omega_d_dot) / h;
  return p;
}

}  // namespace rocksteady::gnc
