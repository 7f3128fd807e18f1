// The flight computer driven through a fake port pair alone: no LCM, no plant library. The fake
// ports wrap the test-only rigid body (tests/common/rigid_body.hpp) and turn the 16 physical
// thrusters back into torque by their own reading of the SPEC §4 wiring.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <type_traits>

#include "fsw/computer/flight_computer.hpp"
#include "fsw_harness.hpp"
#include "heap_counter.hpp"

namespace rocksteady::fsw {
namespace {

using test::M3;
using test::V3;
using test::V4;

// The harness's ports: sensor frames from the truth in the sensors' own frames (the gyro is mounted
// with C_BS), thrusters into torque.
class FakePorts final : public hal::SensorSource, public hal::ThrusterSink {
 public:
  FakePorts(test::Truth& truth, const gnc::GncParams& p, const M3& gyro_c_bs)
      : truth_(truth), c_bs_(gyro_c_bs), b_(gnc::torque_matrix(p.rcs, p.mass_hat.r_so_bcm)) {}

  bool poll(hal::RawSensors& out) override {
    if (polled_ == seq_) return false;
    polled_ = seq_;
    out = hal::RawSensors{};
    out.seq = seq_;
    out.t = truth_.t;
    out.gyro = hal::GyroReading{truth_.t, c_bs_.transpose() * truth_.omega, gyro_valid};
    if (gyro_nan) out.gyro.rate.x() = std::numeric_limits<double>::quiet_NaN();
    out.star = hal::StarTrackerReading{truth_.t, truth_.beta, true};
    return true;
  }
  void write(const hal::ThrusterOutputs& o, std::int64_t seq, double t) override {
    last = o;
    last_seq = seq;
    last_t = t;
    ++writes;
  }
  // The thrusters last written held over h, then the next frame.
  void advance(double h) {
    gnc::Vec8 u = gnc::Vec8::Zero();
    if (last.enabled) {
      for (int pod = 0; pod < 4; ++pod) {
        auto f = [&](int pos) { return last.on[4 * pod + pos] ? last.force[4 * pod + pos] : 0.0; };
        u(2 * pod) = f(0) - f(1);      // tangential pair: positions 0 (+), 1 (-)
        u(2 * pod + 1) = f(2) - f(3);  // axial pair: positions 2 (+), 3 (-)
      }
    }
    truth_.step(h, b_ * u);
    ++seq_;
  }

  bool gyro_valid{true};
  bool gyro_nan{false};
  hal::ThrusterOutputs last{};
  std::int64_t last_seq{-1};
  double last_t{0.0};
  int writes{0};

 private:
  test::Truth& truth_;
  M3 c_bs_;
  Eigen::Matrix<double, 3, 8> b_;
  std::int64_t seq_{0};
  std::int64_t polled_{-1};
};

M3 gyro_mounting() {
  return Eigen::AngleAxisd(0.9, V3(1, 2, -1).normalized()).toRotationMatrix();
}

struct Rig {
  FakeClock clock{0};
  test::Truth truth;
  FlightComputerConfig config;
  std::unique_ptr<FakePorts> ports;
  std::unique_ptr<FlightComputer> computer;

  Rig() {
    config = default_computer_config(test::small_config());
    config.gyro.body_from_sensor = gyro_mounting();
    truth.j = gnc::total_inertia(config.app.gnc.mass_hat);
    ports = std::make_unique<FakePorts>(truth, config.app.gnc, gyro_mounting());
    computer = std::make_unique<FlightComputer>(*ports, *ports);
    const InitResult r = computer->init(config, clock);
    if (!r.ok) throw std::runtime_error(r.field);
  }
  V3 omega_at_frame{V3::Zero()};  // the truth the last frame was read from

  TickReport tick() {
    clock.advance(50000000);
    omega_at_frame = truth.omega;
    const TickReport r = computer->step();
    ports->advance(config.app.gnc.dt);
    return r;
  }
};

TEST(FlightComputer, DespinsIntoHoldThroughAFakePortPairAlone) {
  Rig rig;
  rig.truth.omega = V3(0.3, -0.2, 0.15);
  rig.truth.beta = rocksteady::test::axis_angle(V3(1, 1, 0), 0.7);
  const double w0 = rig.truth.omega.norm();
  ASSERT_TRUE(rig.tick().gnc_ran);
  EXPECT_EQ(rig.computer->mode(), gnc::Mode::kIdle);
  EXPECT_FALSE(rig.ports->last.enabled);  // IDLE: the thrusters were written, all off
  ASSERT_TRUE(rig.computer->submit(test::command(1, Opcode::kSetMode, {1.0})).accepted);
  int ticks = 1;
  bool fired = false;
  while (rig.computer->mode() != gnc::Mode::kHold && ticks < 4000) {
    const TickReport r = rig.tick();
    ++ticks;
    ASSERT_TRUE(r.frame);
    ASSERT_TRUE(r.gnc_ran);
    // Every command answers the frame it was computed from, at that frame's time.
    EXPECT_EQ(rig.ports->last_seq, ticks - 1);
    EXPECT_NEAR(rig.ports->last_t, 0.05 * (ticks - 1), 1e-9);
    fired = fired || rig.ports->last.enabled;
  }
  EXPECT_EQ(rig.computer->mode(), gnc::Mode::kHold);
  EXPECT_TRUE(fired);
  EXPECT_EQ(rig.ports->writes, ticks);  // one thruster write per GNC tick, through the sink only
  EXPECT_LE(rig.truth.omega.norm(), rig.config.app.gnc.guidance.omega_switch * 1.5);
  EXPECT_LT(rig.truth.omega.norm(), 0.1 * w0);
  // The estimate is the body rate: the gyro device applied its mounting between port and core.
  EXPECT_LT((rig.computer->core_output().telemetry.omega_hat - rig.omega_at_frame).norm(), 1e-12);
  // Hold: the attitude converges to the target (zero MRP) through the same ports.
  for (int i = 0; i < 3000; ++i) rig.tick();
  EXPECT_LT(rig.truth.mrp().norm(), 2e-2);
}

TEST(FlightComputer, AGyroWithoutValidReadingsTakesItToSafeWithThrustersOff) {
  Rig rig;
  rig.truth.omega = V3(0.2, 0.0, 0.0);
  rig.tick();
  ASSERT_TRUE(rig.computer->submit(test::command(1, Opcode::kSetMode, {1.0})).accepted);
  for (int i = 0; i < 5; ++i) rig.tick();
  ASSERT_EQ(rig.computer->mode(), gnc::Mode::kDetumble);
  rig.ports->gyro_valid = false;
  for (int i = 0; i < 40; ++i) rig.tick();  // star tracker alone does not carry the rate
  EXPECT_GT(rig.computer->gyro_rejects(), 0u);
  EXPECT_EQ(rig.computer->mode(), gnc::Mode::kSafe);
  EXPECT_FALSE(rig.ports->last.enabled);
  // SAFE keeps commanding every thruster off through the HAL, on every GNC tick: each of the 16 is
  // written off with zero force (a valve driver that loses these commands times out on its own).
  for (int i = 0; i < 20; ++i) {
    const int writes = rig.ports->writes;
    ASSERT_TRUE(rig.tick().gnc_ran);
    EXPECT_EQ(rig.ports->writes, writes + 1);
    EXPECT_EQ(rig.computer->mode(), gnc::Mode::kSafe);
    EXPECT_FALSE(rig.ports->last.enabled);
    for (int t = 0; t < hal::kThrusters; ++t) {
      EXPECT_FALSE(rig.ports->last.on[static_cast<std::size_t>(t)]) << t;
      EXPECT_EQ(rig.ports->last.force[static_cast<std::size_t>(t)], 0.0) << t;
    }
    EXPECT_EQ(rig.ports->last.valve_open, (std::array<bool, 4>{true, true, true, true}));
  }
}

// A NaN in a sensor value is a rejected sample, counted in the health's sensor_rejects (one per
// frame), and reset with the other counters.
TEST(FlightComputer, NanSensorValuesAreCountedInSensorRejects) {
  Rig rig;
  rig.truth.omega = V3(0.2, 0.0, 0.0);
  for (int i = 0; i < 3; ++i) rig.tick();
  EXPECT_EQ(rig.computer->health().sensor_rejects, 0u);
  rig.ports->gyro_nan = true;
  for (int i = 0; i < 7; ++i) rig.tick();
  EXPECT_EQ(rig.computer->health().sensor_rejects, 7u);
  rig.ports->gyro_nan = false;
  for (int i = 0; i < 3; ++i) rig.tick();
  EXPECT_EQ(rig.computer->health().sensor_rejects, 7u);
  ASSERT_TRUE(rig.computer->submit(test::command(1, Opcode::kResetCounters)).accepted);
  rig.tick();
  EXPECT_EQ(rig.computer->health().sensor_rejects, 0u);
}

// A harness reaches the devices only through the ports: the flight computer exposes no device,
// not even a const one, and takes no readings or thruster commands any other way.
template <class T, class = void>
struct HasGyro : std::false_type {};
template <class T>
struct HasGyro<T, std::void_t<decltype(std::declval<T&>().gyro())>> : std::true_type {};
template <class T, class = void>
struct HasStarTracker : std::false_type {};
template <class T>
struct HasStarTracker<T, std::void_t<decltype(std::declval<T&>().star_tracker())>>
    : std::true_type {};
template <class T, class = void>
struct HasBank : std::false_type {};
template <class T>
struct HasBank<T, std::void_t<decltype(std::declval<T&>().thruster_bank())>> : std::true_type {};
template <class T, class = void>
struct TakesSamples : std::false_type {};
template <class T>
struct TakesSamples<T, std::void_t<decltype(std::declval<T&>().tick(
                           std::declval<const Tick&>(), std::declval<const gnc::SensorSample*>()))>>
    : std::true_type {};

TEST(FlightComputer, AHarnessCannotReachTheDevicesExceptThroughPorts) {
  static_assert(!HasGyro<FlightComputer>::value);
  static_assert(!HasStarTracker<FlightComputer>::value);
  static_assert(!HasBank<FlightComputer>::value);
  static_assert(!TakesSamples<FlightComputer>::value);
  static_assert(!std::is_copy_constructible_v<FlightComputer>);
  static_assert(!std::is_default_constructible_v<FlightComputer>);  // ports are required
  // At run time: with nothing on the sensor port, the computer never sees a frame and never fires.
  struct Silent final : hal::SensorSource, hal::ThrusterSink {
    bool poll(hal::RawSensors&) override { return false; }
    void write(const hal::ThrusterOutputs& o, std::int64_t, double) override {
      for (bool on : o.on) any_on = any_on || (o.enabled && on);
      ++writes;
    }
    bool any_on{false};
    int writes{0};
  } silent;
  FakeClock clock{0};
  auto computer = std::make_unique<FlightComputer>(silent, silent);
  FlightComputerConfig cfg = default_computer_config(test::small_config());
  cfg.app.gnc.mode.initial = gnc::Mode::kDetumble;
  ASSERT_TRUE(computer->init(cfg, clock).ok);
  for (int i = 0; i < 40; ++i) {
    clock.advance(50000000);
    const TickReport r = computer->step();
    EXPECT_FALSE(r.frame);
  }
  EXPECT_EQ(computer->health().frames_accepted, 0u);
  EXPECT_EQ(silent.writes, 40);
  EXPECT_FALSE(silent.any_on);                    // no estimate, nothing to fire on
  EXPECT_EQ(computer->mode(), gnc::Mode::kSafe);  // the sensor timeout, from frameless ticks
}

TEST(FlightComputer, RejectsABadDeviceConfigurationNamingTheDevice) {
  FakeClock clock{0};
  test::Truth truth;
  FlightComputerConfig cfg = default_computer_config(test::small_config());
  FakePorts ports(truth, cfg.app.gnc, M3::Identity());
  auto computer = std::make_unique<FlightComputer>(ports, ports);
  cfg.gyro.body_from_sensor = 2.0 * M3::Identity();
  EXPECT_STREQ(computer->init(cfg, clock).field, "gyro");
  cfg = default_computer_config(test::small_config());
  cfg.star_tracker.max_age_s = -1.0;
  EXPECT_STREQ(computer->init(cfg, clock).field, "star_tracker");
  cfg = default_computer_config(test::small_config());
  cfg.thrusters.channel[3].plus = cfg.thrusters.channel[3].minus;
  EXPECT_STREQ(computer->init(cfg, clock).field, "thrusters");
  // Not initialised: a tick reads nothing and writes nothing.
  EXPECT_FALSE(computer->step().gnc_ran);
  EXPECT_EQ(ports.writes, 0);
}

TEST(FlightComputer, AllocatesNothingPerTick) {
  Rig rig;
  rig.truth.omega = V3(0.25, -0.1, 0.05);
  rig.tick();
  ASSERT_TRUE(rig.computer->submit(test::command(1, Opcode::kSetMode, {1.0})).accepted);
  Event e;
  long n = 0;
  {
    const rocksteady::test::HeapArmed armed;
    for (int i = 0; i < 2000; ++i) {
      rig.tick();
      while (rig.computer->pop_event(e)) {
      }
    }
    n = rocksteady::test::heap_allocations();
  }
  EXPECT_EQ(n, 0);
  EXPECT_NE(rig.computer->mode(), gnc::Mode::kIdle);
}

}  // namespace
}  // namespace rocksteady::fsw
