// Test-only truth for identification: the rigid body of tests/common driven by sixteen physical
// thrusters with strength factors, an offset centre of mass, a held random disturbance and a
// noisy gyro. The thruster torque is written out here from the SPEC §4 geometry, separately from
// gnc/estimation and gnc/model.
#pragma once

#include <array>
#include <cmath>
#include <functional>
#include <random>

#include <Eigen/Dense>

#include "rigid_body.hpp"

namespace rocksteady::test {

using V8 = Eigen::Matrix<double, 8, 1>;
using V16 = Eigen::Matrix<double, 16, 1>;

// SPEC §4: pods at 45/135/225/315 deg, radius 2.5 m, plane z = 3 m; channel 2k tangential,
// 2k+1 axial; "+" thruster of channel c is physical thruster 2c, "-" is 2c+1.
struct TruthRcs {
  std::array<V3, 4> pod{};
  std::array<V3, 8> dir{};
  TruthRcs() {
    for (int k = 0; k < 4; ++k) {
      const double th = M_PI / 4 + M_PI / 2 * k;
      pod[k] = V3(2.5 * std::cos(th), 2.5 * std::sin(th), 3.0);
      dir[2 * k] = V3(-std::sin(th), std::cos(th), 0.0);
      dir[2 * k + 1] = V3(0.0, 0.0, 1.0);
    }
  }
  // Body torque of channel forces u with true offset r and true strengths k (per thruster).
  V3 torque(const V8& u, const V3& r, const V16& k) const {
    V3 t = V3::Zero();
    for (int c = 0; c < 8; ++c) {
      if (u(c) == 0.0) continue;
      const int thruster = u(c) > 0 ? 2 * c : 2 * c + 1;
      const V3 force = k(thruster) * u(c) * dir[c];  // sign carried by u(c)
      t += (pod[c / 2] + r).cross(force);
    }
    return t;
  }
};

struct TruthSetup {
  M3 j{M3::Identity()};
  V3 r{V3::Zero()};
  V16 k{V16::Ones()};
  V3 omega0{0.01, 0.02, 0.03};  // SPEC §5
  double dt{0.1};
  double disturbance_sigma{0.0};  // N m per axis, held disturbance_hold_s
  double disturbance_hold_s{10.0};
  double disturbance_phase_s{0.0};  // first change of the held disturbance after this
  double gyro_sigma{0.0};           // rad/s per sample
  V3 gyro_bias{V3::Zero()};         // rad/s, constant, added to every gyro sample
  unsigned long long seed{1};
};

// Steps the truth tick by tick; `command(t, omega_measured)` gives the channel forces for the next
// tick; `each(t, omega_measured, previous_force)` sees what the flight software would see.
class TruthRun {
 public:
  explicit TruthRun(const TruthSetup& s) : s_(s), rng_(s.seed) {
    body_.j = s.j;
    body_.omega = s.omega0;
    k_now_ = s.k;
  }
  template <typename Command, typename Each>
  void run(int ticks, Command command, Each each) {
    V8 previous = V8::Zero();
    V3 dist = V3::Zero();
    double next_draw = 0.0;
    const double first_change = s_.disturbance_phase_s;
    for (int k = 0; k <= ticks; ++k) {
      const double t = k * s_.dt;
      V3 meas = body_.omega + s_.gyro_bias;
      for (int a = 0; a < 3; ++a) meas(a) += s_.gyro_sigma * normal_(rng_);
      each(t, meas, previous);
      if (k == ticks) break;
      const V8 u = command(t, meas);
      if (t >= next_draw - 1e-9) {
        for (int a = 0; a < 3; ++a) dist(a) = s_.disturbance_sigma * normal_(rng_);
        next_draw = (next_draw == 0.0 && first_change > 0.0) ? first_change
                                                             : next_draw + s_.disturbance_hold_s;
      }
      body_.step(s_.dt, rcs_.torque(u, s_.r, k_now_) + dist);
      previous = u;
    }
  }
  RigidBody& body() { return body_; }
  void set_strength(int i, double k) { k_now_(i) = k; }

 private:
  TruthSetup s_;
  RigidBody body_;
  TruthRcs rcs_;
  V16 k_now_{V16::Ones()};
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace rocksteady::test
