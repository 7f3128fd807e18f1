#include "ground/plant/plant.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/LU>

namespace rocksteady::plant {

namespace {

constexpr std::uint64_t kGyroStream = 1;
constexpr std::uint64_t kStarStream = 2;
constexpr std::uint64_t kDisturbanceStream = 3;
constexpr std::uint64_t kGyroBiasStream = 4;

[[noreturn]] void fail(const std::string& field, const std::string& reason) {
  throw std::invalid_argument("plant parameter " + field + ": " + reason);
}

bool spd(const Mat3& m) {
  if (!m.allFinite()) return false;
  if ((m - m.transpose()).norm() > 1e-9 * (1.0 + m.norm())) return false;
  return Eigen::LLT<Mat3>(m).info() == Eigen::Success;
}

bool positive(double v) { return std::isfinite(v) && v > 0.0; }

}  // namespace

const char* to_string(FaultKind k) {
  switch (k) {
    case FaultKind::kNone: return "none";
    case FaultKind::kStuckOff: return "stuck_off";
    case FaultKind::kStuckOn: return "stuck_on";
    case FaultKind::kDegraded: return "degraded";
  }
  return "?";
}

bool parse_fault_kind(const std::string& name, FaultKind& out) {
  for (const FaultKind k : {FaultKind::kStuckOff, FaultKind::kStuckOn, FaultKind::kDegraded}) {
    if (name == to_string(k)) {
      out = k;
      return true;
    }
  }
  return false;
}

std::string check(const ThrusterFault& f) {
  if (f.thruster < 0 || f.thruster >= hal::kThrusters) return "thruster must be in [0, 15]";
  if (f.kind != FaultKind::kStuckOff && f.kind != FaultKind::kStuckOn &&
      f.kind != FaultKind::kDegraded) {
    return "kind must be stuck_off, stuck_on or degraded";
  }
  if (!std::isfinite(f.onset_s) || f.onset_s < 0.0) return "onset_s must be finite and >= 0";
  if (f.kind == FaultKind::kDegraded && !(f.factor > 0.0 && f.factor < 1.0)) {
    return "a degraded thruster's factor must be in (0, 1)";
  }
  return "";
}

std::string describe(const ThrusterFault& f) {
  char b[96];
  if (f.kind == FaultKind::kDegraded) {
    std::snprintf(b, sizeof b, "thruster %d degraded x%.3g at %.6g s", f.thruster, f.factor, f.onset_s);
  } else {
    std::snprintf(b, sizeof b, "thruster %d %s at %.6g s", f.thruster, to_string(f.kind), f.onset_s);
  }
  return b;
}

std::string describe(const std::vector<ThrusterFault>& faults) {
  if (faults.empty()) return "none";
  std::string s;
  for (const ThrusterFault& f : faults) s += (s.empty() ? "" : "; ") + describe(f);
  return s;
}

std::uint64_t stream_seed(std::uint64_t run_seed, std::uint64_t stream_id) {
  // splitmix64 (Steele, Lea, Flood 2014) of the seed mixed with the stream id.
  std::uint64_t z = run_seed + 0x9E3779B97F4A7C15ULL * (stream_id + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

void validate(const PlantParams& p) {
  const gnc::MassProperties& m = p.mass;
  if (!positive(m.m_sc)) fail("mass.m_sc", "must be positive");
  if (!spd(m.j_sc)) fail("mass.j_sc", "not symmetric positive definite");
  if (!spd(m.j_ast)) fail("mass.j_ast", "not symmetric positive definite");
  if (!m.r_scm_so.allFinite() || !m.r_so_bcm.allFinite()) fail("mass", "non-finite offset");
  if (!spd(gnc::total_inertia(m))) fail("mass (J_tot, Eq. 1)", "not symmetric positive definite");
  if (!positive(p.rcs.u_max)) fail("rcs.u_max", "must be positive");
  for (int i = 0; i < gnc::kChannels; ++i) {
    if (!p.rcs.channel_direction[i].allFinite() ||
        std::fabs(p.rcs.channel_direction[i].norm() - 1.0) > 1e-6) {
      fail("rcs.channel_direction", "not a unit vector");
    }
    if (p.rcs.channel_pod[i] < 0 || p.rcs.channel_pod[i] >= gnc::kPods) {
      fail("rcs.channel_pod", "pod index out of range");
    }
  }
  if (!positive(p.isp_s)) fail("isp_s", "must be positive");
  if (!positive(p.g0)) fail("g0", "must be positive");
  if (!positive(p.control_period_s)) fail("control_period_s", "must be positive");
  if (p.substeps < 1 || p.substeps > 10000) fail("substeps", "must be in [1, 10000]");
  if (!std::isfinite(p.disturbance.sigma_nm) || p.disturbance.sigma_nm < 0.0) {
    fail("disturbance.sigma_nm", "must be >= 0");
  }
  if (!positive(p.disturbance.hold_s)) fail("disturbance.hold_s", "must be positive");
  if (!p.disturbance.bias_nm.allFinite()) fail("disturbance.bias_nm", "non-finite value");
  if (!positive(p.sensors.period_s)) fail("sensors.period_s", "must be positive");
  const double ratio = p.sensors.period_s / p.control_period_s;
  if (ratio < 0.999999 || std::fabs(ratio - std::round(ratio)) > 1e-6) {
    fail("sensors.period_s", "must be an integer multiple of the control period");
  }
  if (!std::isfinite(p.sensors.gyro_psd) || p.sensors.gyro_psd < 0.0) {
    fail("sensors.gyro_psd", "noise power must be >= 0");
  }
  if (!std::isfinite(p.sensors.star_psd) || p.sensors.star_psd < 0.0) {
    fail("sensors.star_psd", "noise power must be >= 0");
  }
  if (!p.sensors.gyro_bias.allFinite()) fail("sensors.gyro_bias", "non-finite value");
  if (!std::isfinite(p.sensors.gyro_bias_rw) || p.sensors.gyro_bias_rw < 0.0) {
    fail("sensors.gyro_bias_rw", "must be >= 0");
  }
  for (int i = 0; i < 16; ++i) {
    if (!std::isfinite(p.thruster_strength(i)) || p.thruster_strength(i) < 0.0) {
      fail("thruster_strength", "every factor must be finite and >= 0");
    }
  }
  std::array<bool, hal::kThrusters> faulted{};
  for (std::size_t i = 0; i < p.faults.size(); ++i) {
    const ThrusterFault& f = p.faults[i];
    const std::string why = check(f);
    if (!why.empty()) fail("faults[" + std::to_string(i) + "]", why);
    if (faulted[static_cast<std::size_t>(f.thruster)]) {
      fail("faults[" + std::to_string(i) + "]",
           "thruster " + std::to_string(f.thruster) + " has two faults");
    }
    faulted[static_cast<std::size_t>(f.thruster)] = true;
  }
  if (!std::isfinite(p.command_timeout_s) || p.command_timeout_s < 0.0) {
    fail("command_timeout_s", "must be finite and >= 0 (0: no timeout)");
  }
  if (!p.beta0.allFinite() || std::fabs(p.beta0.norm() - 1.0) > 1e-6) {
    fail("beta0", "not a unit quaternion");
  }
  if (!p.omega0.allFinite()) fail("omega0", "non-finite value");
}

Plant::Plant(const PlantParams& p) : p_(p) {
  validate(p_);
  j_ = gnc::total_inertia(p_.mass);                   // Eq. (1), true values
  j_inv_ = j_.inverse();
  b_ = gnc::torque_matrix(p_.rcs, p_.mass.r_so_bcm);  // SPEC §4, true r_SO/BCM
  sensor_every_ = static_cast<std::uint64_t>(std::llround(p_.sensors.period_s / p_.control_period_s));
  unit_strengths_ = (p_.thruster_strength.array() == 1.0).all();
  reset();
}

void Plant::reset() {
  ticks_ = 0;
  beta_ = p_.beta0.normalized();
  omega_ = p_.omega0;
  fuel_kg_ = 0.0;
  applied_.setZero();
  clipped_ = false;
  clipped_periods_ = 0;
  disturbance_.setZero();
  disturbance_index_ = -1;
  have_sample_ = false;
  sample_tick_ = 0;
  held_ = hal::RawSensors{};
  gyro_rng_.seed(stream_seed(p_.seed, kGyroStream));
  star_rng_.seed(stream_seed(p_.seed, kStarStream));
  dist_rng_.seed(stream_seed(p_.seed, kDisturbanceStream));
  bias_rng_.seed(stream_seed(p_.seed, kGyroBiasStream));
  bias_normal_.reset();
  gyro_bias_ = p_.sensors.gyro_bias;
  gyro_normal_.reset();
  star_normal_.reset();
  dist_normal_.reset();
  faults_ = p_.faults;
  active_.fill(FaultKind::kNone);
  active_factor_.fill(1.0);
  any_active_ = false;
  nominal_last_ = true;
  thrust_.setZero();
  control_torque_.setZero();
  valve_open_ = {true, true, true, true};
  held_cmd_ = hal::ThrusterOutputs{};
  have_cmd_ = false;
  cmd_time_ = 0.0;
  timed_out_ = false;
  timeout_periods_ = 0;
}

std::string Plant::inject(const ThrusterFault& f) {
  std::string why = check(f);
  if (!why.empty()) return why;
  clear_fault(f.thruster);
  faults_.push_back(f);
  return why;
}

void Plant::clear_fault(int thruster) {
  for (auto it = faults_.begin(); it != faults_.end();) {
    it = it->thruster == thruster ? faults_.erase(it) : it + 1;
  }
}

void Plant::clear_faults() { faults_.clear(); }

void Plant::update_active_faults(double t0) {
  active_.fill(FaultKind::kNone);
  active_factor_.fill(1.0);
  any_active_ = false;
  for (const ThrusterFault& f : faults_) {
    if (t0 + 1e-9 < f.onset_s) continue;  // not yet
    const auto i = static_cast<std::size_t>(f.thruster);
    active_[i] = f.kind;
    active_factor_[i] = f.kind == FaultKind::kDegraded ? f.factor : 1.0;
    any_active_ = true;
  }
}

void Plant::set_state(const Vec4& beta, const Vec3& omega) {
  beta_ = beta.normalized();
  omega_ = omega;
}

void Plant::advance(const Vec8& force, bool enabled) {
  // A command for this period: the valve driver's clock restarts.
  have_cmd_ = true;
  cmd_time_ = t();
  timed_out_ = false;
  step_period(force, enabled);
}

void Plant::receive(const hal::ThrusterOutputs& thrusters) {
  held_cmd_ = thrusters;
  have_cmd_ = true;
  cmd_time_ = t();
  valve_open_ = thrusters.valve_open;
}

void Plant::advance() {
  // The valve driver: no new command for command_timeout_s -> every thruster off.
  timed_out_ = have_cmd_ && p_.command_timeout_s > 0.0 &&
               t() - cmd_time_ >= p_.command_timeout_s - 1e-9;
  if (timed_out_) {
    ++timeout_periods_;
    step_period(Vec8::Zero(), false);
  } else {
    step_period(channel_forces(held_cmd_), held_cmd_.enabled);
  }
}

void Plant::advance(const hal::ThrusterOutputs& thrusters) {
  receive(thrusters);
  advance();
}

void Plant::step_period(const Vec8& force, bool enabled) {
  // Per-channel saturation at the true u_max; zero-order hold over the period.
  clipped_ = false;
  for (int i = 0; i < gnc::kChannels; ++i) {
    double f = enabled && std::isfinite(force(i)) ? force(i) : 0.0;
    if (f > p_.rcs.u_max) {
      f = p_.rcs.u_max;
      clipped_ = true;
    } else if (f < -p_.rcs.u_max) {
      f = -p_.rcs.u_max;
      clipped_ = true;
    }
    applied_(i) = f;
  }
  if (clipped_) ++clipped_periods_;

  // Disturbance: a new draw at the start of each hold interval (SPEC §5).
  const double t0 = t();
  const auto index = static_cast<std::int64_t>(std::floor(t0 / p_.disturbance.hold_s + 1e-9));
  while (disturbance_index_ < index) {
    for (int a = 0; a < 3; ++a) disturbance_(a) = p_.disturbance.sigma_nm * dist_normal_(dist_rng_);
    ++disturbance_index_;
  }

  if (!faults_.empty() || any_active_) update_active_faults(t0);
  nominal_last_ = !any_active_ && valve_open_[0] && valve_open_[1] && valve_open_[2] &&
                  valve_open_[3];
  double flow_n = 0.0;  // propellant flow as force, N (Eq. 54)
  if (nominal_last_) {
    // Eq. (2): B u + d. The study's unit strengths keep the original expression, bit for bit.
    control_torque_ = unit_strengths_ ? Vec3(b_ * applied_) : thruster_torque(applied_);
    flow_n = applied_.lpNorm<1>();
  } else {
    // Physical thrusters: thruster 2c is channel c's "+", 2c + 1 its "-" (= 4 pod + position).
    Vec8 delivered;
    for (int c = 0; c < gnc::kChannels; ++c) {
      for (int side = 0; side < 2; ++side) {
        const int i = 2 * c + side;
        const auto k = static_cast<std::size_t>(i);
        const double commanded = side == 0 ? std::max(applied_(c), 0.0) : std::max(-applied_(c), 0.0);
        double fired = commanded;  // what the thruster's valve lets through (propellant flow)
        double thrust = commanded;
        if (!valve_open_[static_cast<std::size_t>(hal::thruster_pod(i))]) {
          fired = thrust = 0.0;  // latch valve closed: no propellant reaches the pod
        } else {
          switch (active_[k]) {
            case FaultKind::kStuckOff: fired = thrust = 0.0; break;
            case FaultKind::kStuckOn: fired = thrust = p_.rcs.u_max; break;
            case FaultKind::kDegraded: thrust = active_factor_[k] * commanded; break;
            case FaultKind::kNone: break;
          }
        }
        thrust_(i) = thrust * p_.thruster_strength(i);
        flow_n += fired;
      }
      delivered(c) = thrust_(2 * c) - thrust_(2 * c + 1);
    }
    control_torque_ = b_ * delivered;
  }
  const Vec3 torque = control_torque_ + disturbance_ + p_.disturbance.bias_nm;
  const double h = p_.control_period_s / p_.substeps;
  for (int s = 0; s < p_.substeps; ++s) att::rk4_step(j_, j_inv_, torque, h, beta_, omega_);
  // Eq. (54): exact for forces held over the period.
  fuel_kg_ += flow_n / (p_.isp_s * p_.g0) * p_.control_period_s;
  ++ticks_;
}

Vec16 Plant::thruster_thrust() const {
  if (!nominal_last_) return thrust_;
  Vec16 f = Vec16::Zero();
  for (int c = 0; c < gnc::kChannels; ++c) {
    const int i = applied_(c) >= 0.0 ? 2 * c : 2 * c + 1;
    f(i) = std::fabs(applied_(c)) * p_.thruster_strength(i);
  }
  return f;
}

Vec8 Plant::delivered_force() const {
  const Vec16 f = thruster_thrust();
  Vec8 u;
  for (int c = 0; c < gnc::kChannels; ++c) u(c) = f(2 * c) - f(2 * c + 1);
  return u;
}

Vec3 Plant::thruster_torque(const Vec8& f) const {
  if (unit_strengths_) return b_ * f;  // B u (the study: every thruster at its nominal strength)
  Vec8 delivered;
  for (int c = 0; c < gnc::kChannels; ++c) {
    delivered(c) = f(c) * p_.thruster_strength(f(c) >= 0.0 ? 2 * c : 2 * c + 1);
  }
  return b_ * delivered;
}

Vec8 Plant::channel_forces(const hal::ThrusterOutputs& thrusters) {
  // The plant's own SPEC §4 wiring (not the flight software's bank): channel 2k = pod k positions
  // 0 (+) and 1 (-), channel 2k+1 = positions 2 (+) and 3 (-); thruster = 4 pod + position.
  Vec8 u = Vec8::Zero();
  if (thrusters.enabled) {
    auto f = [&](int pod, int position) {
      const auto i = static_cast<std::size_t>(hal::thruster_index(pod, position));
      return thrusters.on[i] ? thrusters.force[i] : 0.0;
    };
    for (int pod = 0; pod < gnc::kPods; ++pod) {
      u(2 * pod) = f(pod, 0) - f(pod, 1);
      u(2 * pod + 1) = f(pod, 2) - f(pod, 3);
    }
  }
  return u;
}

hal::RawSensors Plant::read_sensors() {
  hal::RawSensors frame;
  frame.seq = static_cast<std::int64_t>(ticks_);
  frame.t = t();
  if (have_sample_ && ticks_ - sample_tick_ < sensor_every_) {
    frame.gyro = held_.gyro;
    frame.star = held_.star;
    return frame;
  }
  have_sample_ = true;
  sample_tick_ = ticks_;
  const double ts = p_.sensors.period_s;
  const double sigma_w = std::sqrt(p_.sensors.gyro_psd / ts);  // band-limited white noise
  const double sigma_q = std::sqrt(p_.sensors.star_psd / ts);

  // The sensors are aligned with the body frame and sample at the frame time.
  hal::GyroReading& g = frame.gyro;
  g.t = frame.t;
  g.rate = omega_;
  if (p_.sensors.gyro_bias_rw > 0.0 && sample_tick_ > 0) {
    const double step = p_.sensors.gyro_bias_rw * std::sqrt(ts);
    for (int a = 0; a < 3; ++a) gyro_bias_(a) += step * bias_normal_(bias_rng_);
  }
  if (p_.sensors.gyro_bias_rw > 0.0 || !p_.sensors.gyro_bias.isZero(0.0)) g.rate += gyro_bias_;
  if (sigma_w > 0.0) {
    for (int a = 0; a < 3; ++a) g.rate(a) += sigma_w * gyro_normal_(gyro_rng_);
  }
  g.valid = true;
  hal::StarTrackerReading& st = frame.star;
  st.t = frame.t;
  Vec3 q = mrp();
  if (sigma_q > 0.0) {
    for (int a = 0; a < 3; ++a) q(a) += sigma_q * star_normal_(star_rng_);
    st.quat = att::mrp_to_quat(q);
  } else {
    st.quat = beta_(3) < 0.0 ? Vec4(-beta_) : beta_;
  }
  st.valid = true;
  held_ = frame;
  return frame;
}

}  // namespace rocksteady::plant
