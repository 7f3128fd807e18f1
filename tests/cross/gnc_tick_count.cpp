// Instruction-count probe of one Gnc::step on a Linux target (used by scripts/cross.sh under
// qemu-aarch64 -singlestep -d exec). Runs the firmware's scenario (study parameters, true mass
// properties, the firmware's rigid-body plant) for `ticks` ticks in the requested mode and brackets
// every measured Gnc::step between two marker functions; an empty bracket gives the baseline to
// subtract. The trace counter (count_insns.awk) counts the instructions between the markers.
//
// Usage: gnc_tick_count detumble|hold TICKS
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/rigid_body.hpp"
#include "gnc/gnc.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"

namespace gnc = rocksteady::gnc;

// Markers: distinct, never inlined, visible in the emulator's trace by name.
extern "C" __attribute__((noinline)) void rs_probe_begin() { __asm__ volatile("" ::: "memory"); }
extern "C" __attribute__((noinline)) void rs_probe_end() { __asm__ volatile("" ::: "memory"); }

namespace {

gnc::GncParams g_params;
gnc::Gnc g_gnc;
gnc::GncOutput g_out;

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 || (std::strcmp(argv[1], "detumble") != 0 && std::strcmp(argv[1], "hold") != 0)) {
    std::fprintf(stderr, "usage: %s detumble|hold TICKS\n", argv[0]);
    return 2;
  }
  const bool hold = std::strcmp(argv[1], "hold") == 0;
  const long ticks = std::strtol(argv[2], nullptr, 10);

  g_params = gnc::study_gnc_params(200.0);
  if (!g_gnc.init(g_params).ok) return 3;
  const gnc::MassProperties truth = gnc::study_true_mass_properties();
  const gnc::Mat38 b_true = gnc::torque_matrix(g_params.rcs, truth.r_so_bcm);
  // DETUMBLE from the study's initial state; HOLD from a slow residual rate (below omega_switch).
  const gnc::Vec3 omega0 = hold ? gnc::Vec3(1e-4, -2e-4, 1.5e-4) : gnc::Vec3(0.01, 0.02, 0.03);
  rocksteady::firmware::RigidBody body(
      gnc::total_inertia(truth),
      rocksteady::firmware::RigidBody::quaternion_from_mrp(gnc::Vec3(0.05, 0.04, 0.03)), omega0);
  const gnc::Mode want = hold ? gnc::Mode::kHold : gnc::Mode::kDetumble;

  // Baseline: an empty bracket (marker call overhead only).
  rs_probe_begin();
  rs_probe_end();

  double t = 0.0;
  long in_mode = 0;
  for (long k = 0; k <= ticks; ++k) {
    gnc::GncCommands cmd;
    cmd.has_mode_request = k == 0;
    cmd.mode_request = want;
    gnc::SensorSample s;
    s.t = t;
    s.gyro_rate = body.omega();
    s.gyro_valid = true;
    s.star_quat = body.beta();
    s.star_valid = true;
    if (k == 0) {
      g_gnc.step(s, cmd, g_out);  // the mode change: not measured
    } else {
      rs_probe_begin();
      g_gnc.step(s, cmd, g_out);
      rs_probe_end();
      if (g_gnc.mode() == want) ++in_mode;
    }
    body.step(g_params.dt, b_true * g_out.command.force);
    t += g_params.dt;
  }
  std::printf("gnc_tick_count: %s, %ld measured ticks, %ld in %s, |w| %.4e -> %.4e rad/s\n",
              argv[1], ticks, in_mode, gnc::to_string(want), omega0.norm(), body.omega().norm());
  return in_mode == ticks ? 0 : 1;
}
