// The plant: Rocksteady's truth model of the spacecraft + captured asteroid (ground equipment).
//
// - rigid-body attitude dynamics, SPEC Eq. (2), with the TRUE mass properties (Eq. 1) and the TRUE
//   torque matrix B (SPEC §4, built from the true r_SO/BCM); state: quaternion (Eq. 3) + body rate;
//   fixed-step RK4 with `substeps` steps per control period;
// - thruster channel forces held constant over each control period (zero-order hold), clipped per
//   channel at the true u_max; fuel integrated per Eq. (54);
// - external disturbance (SPEC §5): body-frame zero-mean Gaussian, per-axis sigma, a new draw every
//   `hold_s`, plus an optional constant bias;
// - sensors (SPEC §5, Table 3): gyro with per-axis noise sigma = sqrt(P(dw)/T_s), star tracker with
//   per-axis MRP noise sigma = sqrt(P(dq)/T_s) added to the true (shadow-normalised) MRP and delivered
//   as a unit quaternion; a new sample every sensor period T_s, held in between;
// - a gyro bias (constant + random walk on its own stream) and a strength factor per physical
//   thruster (16), both off by default (zero, one), in which case the code path is the study's;
// - thruster faults per physical thruster (stuck off, stuck on, degraded), each from an onset time,
//   one latch valve per pod (a closed pod's four thrusters produce nothing, a stuck-on one
//   included), and the valve driver's command timeout (thrusters off when commands stop); none of
//   them by default, in which case the code path is the study's, bit for bit;
// - every random stream (gyro, star tracker, disturbance, gyro bias) seeded from the run's seed: a
//   run is bit-for-bit repeatable.
#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "ground/plant/attitude.hpp"
#include "hal/readings.hpp"

namespace rocksteady::plant {

using Vec8 = Eigen::Matrix<double, 8, 1>;
using Mat38 = Eigen::Matrix<double, 3, 8>;

struct DisturbanceParams {
  double sigma_nm{0.57735026918962576};  // per axis, N m (1/sqrt(3): |d| ~ 1 N m)
  double hold_s{10.0};                   // a new draw every hold_s
  Vec3 bias_nm{Vec3::Zero()};            // constant body-frame bias torque, N m
};

struct SensorParams {
  double period_s{0.1};    // T_s; an integer multiple of the control period
  double gyro_psd{0.0};    // P(dw), rad^2/s^2 (per axis)
  double star_psd{0.0};    // P(dq), MRP^2 (per axis)
  // Gyro bias (Farrenkopf's model): b(0) = gyro_bias, b advancing by a random walk of
  // gyro_bias_rw rad/s^(3/2) (a draw per sensor sample from its own stream). Zero in the study.
  Vec3 gyro_bias{Vec3::Zero()};  // rad/s
  double gyro_bias_rw{0.0};
};

// Sixteen physical thrusters: thruster 2c is channel c's "+" thruster, 2c+1 its "-" (SPEC §4).
using Vec16 = Eigen::Matrix<double, 16, 1>;

// A thruster fault (ground truth; the flight software never sees it). Physical thruster index
// 4 * pod + position (hal/readings.hpp), which is also 2c ("+") and 2c + 1 ("-") of channel c.
enum class FaultKind : std::uint8_t {
  kNone = 0,
  kStuckOff = 1,  // produces nothing whatever is commanded (and uses no propellant)
  kStuckOn = 2,   // full thrust u_max whatever is commanded, while its pod's latch valve is open
  kDegraded = 3,  // delivers factor x the commanded thrust, 0 < factor < 1
};
const char* to_string(FaultKind k);  // "none", "stuck_off", "stuck_on", "degraded"
// Parses the names of to_string (not "none"). False for anything else.
bool parse_fault_kind(const std::string& name, FaultKind& out);

struct ThrusterFault {
  int thruster{0};                      // 0..15
  FaultKind kind{FaultKind::kStuckOff};
  double onset_s{0.0};                  // plant time from which the fault acts, s (>= 0)
  double factor{1.0};                   // kDegraded: thrust factor in (0, 1); otherwise unused
};
// Empty when the fault is valid, else the reason.
std::string check(const ThrusterFault& f);
// "thruster 3 stuck_on at 60 s", "thruster 5 degraded x0.5 at 100 s"; a list joined by "; ".
std::string describe(const ThrusterFault& f);
std::string describe(const std::vector<ThrusterFault>& faults);  // "none" when empty

struct PlantParams {
  gnc::MassProperties mass{gnc::study_true_mass_properties()};  // true mass properties
  gnc::RcsLayout rcs{gnc::study_rcs_layout(200.0)};              // true geometry and u_max
  double isp_s{287.0};  // Eq. (54)
  double g0{9.8};
  double control_period_s{0.1};  // forces are held for one period
  int substeps{1};               // RK4 steps per control period
  DisturbanceParams disturbance{};
  SensorParams sensors{};
  // True strength factor of each physical thruster: the force it delivers is k_i times the
  // commanded one (1 in the study; fuel is counted on the commanded force).
  Vec16 thruster_strength{Vec16::Ones()};
  // Thruster faults, at most one per thruster (none in the study).
  std::vector<ThrusterFault> faults{};
  // The valve driver's command timeout, s of plant time: when no new thruster command has arrived
  // for this long, every thruster is switched off (latch valves keep their state). 0: off (the
  // last command is held forever, the study's harness behaviour).
  double command_timeout_s{0.0};
  Vec4 beta0{0.0, 0.0, 0.0, 1.0};  // initial attitude, unit quaternion of F_B in F_I
  Vec3 omega0{Vec3::Zero()};        // initial body rate, rad/s
  std::uint64_t seed{1};
};

// Throws std::invalid_argument naming the first bad field.
void validate(const PlantParams& p);

class Plant {
 public:
  explicit Plant(const PlantParams& p);  // validates, then reset()
  void reset();                          // initial state, time 0, streams re-seeded
  const PlantParams& params() const { return p_; }

  // One control period with a fresh command: clip each channel at u_max (zeros when !enabled), hold
  // the forces (and the disturbance) for the period, apply the thruster faults and the latch valves
  // (as last set), RK4 with `substeps` steps, integrate fuel (Eq. 54).
  void advance(const Vec8& force, bool enabled);

  // The valve driver: latch a new command (16 physical thrusters and the four latch valves) at the
  // current plant time. The plant's own SPEC §4 wiring maps the thrusters onto the channels;
  // nothing fires when !thrusters.enabled. The valves take the commanded state.
  void receive(const hal::ThrusterOutputs& thrusters);
  // One control period with the command last received (all off before any): when
  // command_timeout_s > 0 and no command arrived for that long, every thruster is off.
  void advance();
  // receive() then advance(): a fresh command for this period.
  void advance(const hal::ThrusterOutputs& thrusters);
  // That mapping: the signed channel forces of a thruster firing (zeros when disabled).
  static Vec8 channel_forces(const hal::ThrusterOutputs& thrusters);

  // The device readings the sensors deliver now, as one frame numbered by the control period: a
  // fresh gyro and star-tracker reading at each sensor period, the held ones in between (their `t`
  // is the time they were taken).
  hal::RawSensors read_sensors();

  // Truth.
  double t() const { return static_cast<double>(ticks_) * p_.control_period_s; }
  std::uint64_t ticks() const { return ticks_; }
  const Vec4& beta() const { return beta_; }
  const Vec3& omega() const { return omega_; }
  Vec3 mrp() const { return att::quat_to_mrp(beta_); }  // shadow-normalised, |q| <= 1
  double fuel_kg() const { return fuel_kg_; }
  const Vec8& applied_force() const { return applied_; }   // after clipping, last period
  bool clipped() const { return clipped_; }                  // a channel was clipped last period
  std::uint64_t clipped_periods() const { return clipped_periods_; }
  const Vec3& disturbance() const { return disturbance_; }  // random part held last period
  const Mat3& inertia() const { return j_; }
  const Vec3& gyro_bias() const { return gyro_bias_; }  // true bias of the current sample
  // The body torque the thrusters deliver for channel forces f (after clipping), with the true
  // strength factors.
  Vec3 thruster_torque(const Vec8& f) const;
  const Mat38& torque_matrix() const { return b_; }
  Vec3 angular_momentum_inertial() const { return att::quat_to_matrix(beta_) * (j_ * omega_); }
  double kinetic_energy() const { return 0.5 * omega_.dot(j_ * omega_); }

  // Test hook: overwrite the state (beta is normalised).
  void set_state(const Vec4& beta, const Vec3& omega);

  // --- Faults and valves -------------------------------------------------------------------------
  // Adds a fault at run time (PIL fault injection); it replaces any fault of that thruster, and acts
  // from its onset (at once when the onset has passed). Returns the reason when rejected (empty:
  // accepted).
  std::string inject(const ThrusterFault& f);
  void clear_fault(int thruster);  // removes that thruster's fault (no-op when out of range)
  void clear_faults();
  const std::vector<ThrusterFault>& faults() const { return faults_; }
  // The fault acting on each thruster during the last period (kNone before the onset).
  const std::array<FaultKind, hal::kThrusters>& active_faults() const { return active_; }
  // Latch valves, one per pod (open by default); set by receive(), or directly (test hook).
  const std::array<bool, gnc::kPods>& valves() const { return valve_open_; }
  void set_valves(const std::array<bool, gnc::kPods>& open) { valve_open_ = open; }
  // Force delivered by each physical thruster last period, N (after faults, valves, strengths).
  Vec16 thruster_thrust() const;
  // Signed channel forces delivered last period (delivered "+" minus delivered "-"), N.
  Vec8 delivered_force() const;
  // Body torque the thrusters delivered last period (the true B times the delivered forces), N m.
  const Vec3& control_torque() const { return control_torque_; }
  // The valve driver switched everything off last period for want of commands; periods so far.
  bool command_timed_out() const { return timed_out_; }
  std::uint64_t timeout_periods() const { return timeout_periods_; }

 private:
  PlantParams p_;
  Mat3 j_{Mat3::Identity()};
  Mat3 j_inv_{Mat3::Identity()};
  Mat38 b_{Mat38::Zero()};
  std::uint64_t sensor_every_{1};  // control periods per sensor period

  std::uint64_t ticks_{0};
  Vec4 beta_{0.0, 0.0, 0.0, 1.0};
  Vec3 omega_{Vec3::Zero()};
  double fuel_kg_{0.0};
  Vec8 applied_{Vec8::Zero()};
  bool clipped_{false};
  std::uint64_t clipped_periods_{0};

  // Faults, valves, valve driver.
  std::vector<ThrusterFault> faults_{};
  std::array<FaultKind, hal::kThrusters> active_{};
  std::array<double, hal::kThrusters> active_factor_{};
  bool any_active_{false};
  bool nominal_last_{true};  // last period took the study's code path (no fault, valves open)
  Vec16 thrust_{Vec16::Zero()};  // delivered per thruster (fault path)
  Vec3 control_torque_{Vec3::Zero()};
  std::array<bool, gnc::kPods> valve_open_{true, true, true, true};
  hal::ThrusterOutputs held_cmd_{};
  bool have_cmd_{false};
  double cmd_time_{0.0};
  bool timed_out_{false};
  std::uint64_t timeout_periods_{0};
  void update_active_faults(double t0);
  void step_period(const Vec8& force, bool enabled);

  Vec3 disturbance_{Vec3::Zero()};
  std::int64_t disturbance_index_{-1};  // which hold interval the current draw belongs to

  bool have_sample_{false};
  std::uint64_t sample_tick_{0};
  hal::RawSensors held_{};

  std::mt19937_64 gyro_rng_;
  std::mt19937_64 star_rng_;
  std::mt19937_64 dist_rng_;
  std::mt19937_64 bias_rng_;
  std::normal_distribution<double> bias_normal_{0.0, 1.0};
  Vec3 gyro_bias_{Vec3::Zero()};
  bool unit_strengths_{true};
  std::normal_distribution<double> gyro_normal_{0.0, 1.0};
  std::normal_distribution<double> star_normal_{0.0, 1.0};
  std::normal_distribution<double> dist_normal_{0.0, 1.0};
};

// A 64-bit seed for one named random stream of a run (splitmix64 of the run seed and stream id).
std::uint64_t stream_seed(std::uint64_t run_seed, std::uint64_t stream_id);

}  // namespace rocksteady::plant
