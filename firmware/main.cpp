// Bare-metal demonstration of the flight core: the study's parameter table compiled in, Gnc::init,
// then DETUMBLE commanded on tick 0 and the loop closed against a small built-in rigid-body
// propagator (true mass properties, Eq. 2). Progress goes to the semihosting console; the exit code
// is 0 when the despin progressed as expected.
//
// Options (QEMU: -semihosting-config enable=on,arg=firmware,arg=seconds=300,...):
//   seconds=N     simulated time (default ROCKSTEADY_FW_SECONDS)
//   print=N       print period in simulated seconds (default 1000)
//   goal=despin   only require |w| to fall (default goal=hold: DETUMBLE must also hand over to HOLD)
//   start=hold    start from a slow residual rate and command HOLD instead (instruction counts of
//                 the HOLD phase without simulating the despin); success = HOLD kept throughout
//   modules=all   every flight-core module on (the budget of DEVELOPERS.md): the MEKF, on-line
//                 identification with automatic model adoption, fault detection, the L1 allocator
//   excite=on     with modules=all: the identification excitation too (an option, off in gnc.yaml;
//                 gnc/estimation/README.md §I.6), with gnc.yaml's settings
//   stuck=N       thruster N (0-15: channel N/2, + for even N) stuck on at u_max from onset=T s
//                 (default 1000) until the flight closes its pod's latch valve: the fault detector,
//                 its isolation test, the valve and the reallocation run on the counted ticks;
//                 success then also needs that thruster, and only it, confirmed stuck on
//   alloc=pinv    with modules=all: the pseudoinverse allocator (gnc.yaml's) instead of L1
//   degraded=N    thruster N delivers half of what is commanded from onset=T s: the partial-loss
//                 confirmation (gnc/fdi/README.md F18) runs on the counted ticks; success then also
//                 needs that thruster, and only it, confirmed degraded
//   survey=S      with modules=all: the jet survey (gnc/fdi/README.md F36) every S s (default
//                 20000, gnc.yaml's; 0 off), so that its checks run on the counted ticks (in HOLD
//                 only, F43; inside the budget: DEVELOPERS.md)
//   balance=U     with modules=all: the channel balance tests (gnc/fdi/README.md F61) with a kick
//                 of U micro-rad/s (default 0: off, as gnc.yaml)
//
// Every counted Gnc::step is bracketed by rs_probe_begin()/rs_probe_end(), so an emulator trace
// (qemu -singlestep -d exec,nochain + tests/cross/count_insns.awk) counts its instructions exactly.
#include <cmath>
#include <cstdint>
#include <cstring>

#include "board.hpp"
#include "gnc/gnc.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "rigid_body.hpp"
#include "semihosting.hpp"

#ifndef ROCKSTEADY_FW_SECONDS
#define ROCKSTEADY_FW_SECONDS 20000
#endif

namespace gnc = rocksteady::gnc;
namespace fw = rocksteady::firmware;
namespace board = rocksteady::firmware::board;

namespace {

// Static storage for everything large: the stack holds only a tick's temporaries.
gnc::GncParams g_params;
gnc::Gnc g_gnc;
gnc::GncOutput g_out;
char g_cmdline[128];

struct Options {
  std::uint32_t seconds{ROCKSTEADY_FW_SECONDS};
  std::uint32_t print_every_s{1000};
  bool require_hold{true};
  bool start_hold{false};
  bool all_modules{false};
  bool excite{false};
  int stuck{-1};                // thruster stuck on (-1: none)
  int degraded{-1};             // thruster at half strength (-1: none)
  bool pinv{false};             // modules=all with the pseudoinverse allocator
  std::uint32_t onset_s{1000};  // ... from this simulated time
  std::uint32_t survey_s{20000};  // (F36) jet survey interval, 0 off (gnc.yaml's 20 000 s)
  std::uint32_t balance_urad_s{0};  // (F61) balance test kick, micro-rad/s (0 off, gnc.yaml's)
};

// Parses "key=value" tokens of the semihosting command line (unknown tokens are ignored).
Options parse_options() {
  Options o;
  if (!fw::host_cmdline(g_cmdline, sizeof(g_cmdline))) return o;
  const char* p = g_cmdline;
  while (*p != '\0') {
    while (*p == ' ') ++p;
    const char* tok = p;
    while (*p != '\0' && *p != ' ') ++p;
    const auto len = static_cast<std::size_t>(p - tok);
    auto value_of = [&](const char* key) -> const char* {
      const std::size_t k = std::strlen(key);
      return (len > k && std::strncmp(tok, key, k) == 0) ? tok + k : nullptr;
    };
    auto to_u32 = [](const char* s) {
      std::uint32_t v = 0;
      while (*s >= '0' && *s <= '9') v = v * 10U + static_cast<std::uint32_t>(*s++ - '0');
      return v;
    };
    if (const char* v = value_of("seconds=")) o.seconds = to_u32(v);
    if (const char* v = value_of("print=")) o.print_every_s = to_u32(v) > 0 ? to_u32(v) : 1U;
    if (const char* v = value_of("goal=")) o.require_hold = std::strncmp(v, "despin", 6) != 0;
    if (const char* v = value_of("start=")) o.start_hold = std::strncmp(v, "hold", 4) == 0;
    if (const char* v = value_of("modules=")) o.all_modules = std::strncmp(v, "all", 3) == 0;
    if (const char* v = value_of("excite=")) o.excite = std::strncmp(v, "on", 2) == 0;
    if (const char* v = value_of("stuck=")) {
      const std::uint32_t n = to_u32(v);
      o.stuck = n < 16U ? static_cast<int>(n) : -1;
    }
    if (const char* v = value_of("alloc=")) o.pinv = std::strncmp(v, "pinv", 4) == 0;
    if (const char* v = value_of("degraded=")) {
      const std::uint32_t n = to_u32(v);
      o.degraded = n < 16U ? static_cast<int>(n) : -1;
    }
    if (const char* v = value_of("onset=")) o.onset_s = to_u32(v);
    if (const char* v = value_of("survey=")) o.survey_s = to_u32(v);
    if (const char* v = value_of("balance=")) o.balance_urad_s = to_u32(v);
  }
  return o;
}

gnc::SensorSample sample_of(const fw::RigidBody& body, double t) {
  gnc::SensorSample s;
  s.t = t;
  s.gyro_rate = body.omega();
  s.gyro_valid = true;
  s.star_quat = body.beta();
  s.star_valid = true;
  return s;
}

// One Gnc::step with the stack below the caller painted first: returns the bytes of stack the
// step used below this function's frame (its own call frame included).
__attribute__((noinline)) std::uint32_t step_measuring_stack(const gnc::SensorSample& s,
                                                             const gnc::GncCommands& c) {
  board::paint_stack_below_sp();
  const std::uintptr_t sp = board::current_sp();
  g_gnc.step(s, c, g_out);
  return static_cast<std::uint32_t>(sp - board::lowest_stack_address_used());
}

// What a tick did, for the list of the largest ticks: counters before and after the step.
struct Snapshot {
  std::uint32_t windows{0};
  std::uint32_t scored{0};
  std::uint32_t adoptions{0};
  std::uint32_t reinflations{0};
  bool held_zero{false};
  int fdi_best{-1};
  bool fdi_suspecting{false};
  std::uint32_t valves{0};
};

Snapshot snapshot() {
  Snapshot s;
  const auto& id = g_gnc.identifier();
  s.windows = id.counters().windows;
  s.scored = id.fault_torque().scored;
  s.held_zero = id.fault_torque().held_zero;
  s.reinflations = id.counters().reinflations;
  s.adoptions = g_gnc.model_adoptions();
  s.fdi_best = g_gnc.fault_detector().status().best;
  s.fdi_suspecting = g_gnc.fault_detector().suspecting();
  for (std::size_t p = 0; p < g_gnc.valve_open().size(); ++p) {
    if (g_gnc.valve_open()[p]) s.valves |= 1U << p;
  }
  return s;
}

struct Events {
  char text[12]{};
};

Events tick_events(const Snapshot& a, const Snapshot& b) {
  Events e;
  std::size_t n = 0;
  auto add = [&e, &n](bool on, char c) {
    if (on && n + 1 < sizeof(e.text)) e.text[n++] = c;
  };
  add(b.windows != a.windows, 'W');
  add(b.scored != a.scored, 'S');
  add(b.held_zero != a.held_zero, 'Z');
  add(b.adoptions != a.adoptions, 'A');
  add(b.reinflations != a.reinflations, 'R');
  add(b.valves != a.valves, 'V');
  add(b.fdi_best != a.fdi_best || b.fdi_suspecting != a.fdi_suspecting, 'F');
  if (n == 0) e.text[n++] = '-';
  e.text[n] = '\0';
  return e;
}

struct TickNote {
  std::uint32_t k{0};
  std::uint32_t counts{0};
  std::uint8_t mode{0};
  Events what{};
};
constexpr std::size_t kWorst = 8;

}  // namespace

// Trace markers (see the header comment): distinct, never inlined.
extern "C" __attribute__((noinline)) void rs_probe_begin() { __asm__ volatile("" ::: "memory"); }
extern "C" __attribute__((noinline)) void rs_probe_end() { __asm__ volatile("" ::: "memory"); }

int firmware_main() {
  fw::Line line;
  const Options opt = parse_options();

  g_params = gnc::study_gnc_params(200.0);
  if (opt.all_modules) {
    g_params.estimator.kind = gnc::EstimatorKind::kMekf;
    g_params.mekf.gyro_arw = 1e-6;
    g_params.mekf.star_sigma = 4e-4;
    g_params.mekf.rate_cutoff = 0.02 * 3.14159265358979323846;  // the rate stage (M8), as flown
    g_params.allocator = opt.pinv ? gnc::AllocatorKind::kPseudoInverse : gnc::AllocatorKind::kL1;
    g_params.identification.enabled = true;
    g_params.identification.adopt = gnc::ModelAdoption::kAuto;
    g_params.fdi.enabled = true;
    g_params.fdi.identified_isolation = true;  // (F14) the identifier's fault torque, as flown
    g_params.fdi.degraded_min_loss = 0.1;      // (F18) partial losses of thrust, as flown
    g_params.fdi.degraded_loss_projection = true;  // (F51) the loss beyond the signature's error along itself
    g_params.fdi.check_llr = 5.0;              // (F19) jet checks, as flown
    g_params.fdi.check_max_model_error = 0.5;  // ... against the model's stated 1 sigma, as flown
    g_params.fdi.check_min_llr = 5.0;          // (F24) ... when the check can move the evidence
    g_params.fdi.check_fit_on_suspicion = true;  // (F31) ... and not for an evident fault elsewhere
    g_params.fdi.check_quiet_start = true;       // (F34) ... nor on a suspicious window
    g_params.fdi.check_score_unfit = true;       // (F35) an unfit check window is scored
    g_params.fdi.check_blocker = true;           // (F37) the jet blocking a stuck-off leader checked
    g_params.fdi.episode_restart_stale = true;   // (F38) a stale episode restarted
    g_params.fdi.episode_restart_leader = true;  // (F41) ... and one a new leader's fault postdates
    g_params.fdi.survey_interval_s = static_cast<double>(opt.survey_s);  // (F36) as flown: 20 000 s
    g_params.fdi.model_rel_floor = 0.005;      // the model's relative error floor, as flown
    g_params.fdi.model_floor_gyroscopic = true;   // (F22) ... on both terms, as flown
    g_params.fdi.probe_windows = 1;            // isolation tests of one window ...
    g_params.fdi.probe_aligned = true;         // (F27) ... flown closed throughout, as flown
    g_params.fdi.probe_partial_rival = true;   // (F29) ... read against partial losses
    g_params.fdi.probe_read_closed = true;     // (F32) ... and first on the closed window
    g_params.fdi.probe_read_elsewhere = true;  // (F40) ... which may name another pod's jet
    g_params.fdi.probe_start_llr = 8.0;        // (F52) ... and may start below confirm_llr
    g_params.fdi.check_model_null_space = true;  // (F42) checks in the identified model's null space
    g_params.fdi.survey_hold_only = true;  // (F43) the survey in HOLD only
    g_params.fdi.survey_max_kick_rad_s = 5.0e-5;  // (F44) ... and no survey check that may kick the rate
    g_params.fdi.survey_noise_kick = true;  // (F48) ... nor where the gyro is too noisy for one
    g_params.fdi.check_long_ticks = 1000;  // (F49) ... where it is, every check in HOLD one long window
    g_params.fdi.check_long_energy = 80.0;
    g_params.fdi.check_long_evidence_energy = 320.0;
    g_params.fdi.check_long_reach = 0.8;  // (F50) ... or this fraction of the energy the centre of mass caps
    g_params.fdi.check_kick_after_fault = true;  // (F56) after a fault, evidence checks in the kick bound
    g_params.fdi.survey_loss_llr = 2.5;  // (F57) a jet with partial-loss evidence is not verified by its energy
    g_params.fdi.total_loss_sigmas = 2.0;  // (F58) a loss 2 sigma below the total-loss floor is partial
    g_params.fdi.after_fault_max_j_rel = 0.01;  // (F59) after a fault, losses and checks on a confident model
    g_params.fdi.balance.kick_rad_s = 1e-6 * static_cast<double>(opt.balance_urad_s);  // (F61) off, as gnc.yaml
    g_params.fdi.balance.quiet_ticks = 300;
    g_params.fdi.centred_gyro_noise = true;    // (F28) the gyro's variance sigma_g^2, as flown
    g_params.fdi.suspect_chi2 = 30.66;         // ... and the suspicion at 1 - 1e-6, as flown
    g_params.fdi.detect_early_ticks = 3;       // (F33) early detection, as flown
    g_params.fdi.skip_onset_window = true;     // (F21) the onset window not scored: 5-tick windows
    g_params.fdi.onset_restart = true;         // (F45) ... ended at its early suspicion, as flown
    g_params.fdi.episode_restart = true;       // (F25) the episode since the fault showed, as flown
    // The identifier as flown (gnc.yaml) for this gyro's noise: the noisy sensors' 60 s window, the
    // second-order term (I20), the gate (I18), the noise correction (I25), the gyro bias (I17).
    gnc::apply_flight_identification_settings(g_params, g_params.mekf.gyro_arw / std::sqrt(g_params.dt));
    if (opt.excite) {  // gnc.yaml's excitation settings (§I.6)
      g_params.identification.excitation.enabled = true;
      g_params.identification.excitation.force_n = gnc::Vec3(100.0, 100.0, 400.0);
      g_params.identification.excitation.duration_s = 600.0;
      g_params.identification.excitation.r_sigma_stop_m = 0.005;
      g_params.identification.excitation.start_after_s = 60.0;
      g_params.identification.excitation.r_sigma_target_m = 0.01;  // (X7)
      g_params.identification.excitation.inertia_torque_nm = gnc::Vec3(100.0, 100.0, 100.0);  // (X8)
    }
  }
  const gnc::ParamCheck check = g_gnc.init(g_params);
  if (!check.ok) {
    line.str("firmware: parameter table rejected: ").str(check.field).str(": ").str(check.reason);
    line.flush();
    return 2;
  }

  // Truth: the study's true mass properties (equal to the flight estimate in this table) and the
  // true torque matrix B, Eq. (2); initial state of SPEC section 5.
  const gnc::MassProperties truth = gnc::study_true_mass_properties();
  const gnc::Mat38 b_true = gnc::torque_matrix(g_params.rcs, truth.r_so_bcm);
  fw::RigidBody body(gnc::total_inertia(truth),
                     fw::RigidBody::quaternion_from_mrp(gnc::Vec3(0.05, 0.04, 0.03)),
                     opt.start_hold ? gnc::Vec3(1e-4, -2e-4, 1.5e-4) : gnc::Vec3(0.01, 0.02, 0.03));
  const gnc::Mode first_mode = opt.start_hold ? gnc::Mode::kHold : gnc::Mode::kDetumble;

  board::counter_start();
  // The empty bracket first: the trace counter's baseline (marker call overhead).
  rs_probe_begin();
  rs_probe_end();
  const std::uint32_t kCalIterations = 100000;
  const std::uint32_t cal_counts = board::counter_for_known_loop(kCalIterations);

  line.str("firmware: Cortex-M7 (fpv5-d16), sizeof(Gnc)=").u32(sizeof(gnc::Gnc))
      .str(" B, sizeof(GncParams)=").u32(sizeof(gnc::GncParams))
      .str(" B, dt=").fix(g_params.dt, 2).str(" s, run ").u32(opt.seconds).str(" s")
      .str(opt.all_modules ? ", modules: MEKF + identification + FDI + " : ", modules: study")
      .str(opt.all_modules ? (opt.pinv ? "pseudoinverse" : "L1") : "")
      .str(opt.all_modules && opt.excite ? " + excitation" : "")
      .str(opt.stuck >= 0 ? ", a thruster stuck on" : "");
  line.flush();

  const double dt = g_params.dt;
  const auto ticks = static_cast<std::uint32_t>(static_cast<double>(opt.seconds) / dt + 0.5);
  const auto print_ticks =
      static_cast<std::uint32_t>(static_cast<double>(opt.print_every_s) / dt + 0.5);
  const double w0 = body.omega().norm();
  double last_printed_w = w0;
  bool monotone = true;
  bool reached_hold = false;
  bool always_hold = true;
  std::uint32_t stack_max = 0;
  std::uint32_t stack_first = 0;
  // Per mode (the mode after the step): counter totals, maxima and ticks counted.
  std::uint64_t counts_total[gnc::kModeCount] = {};
  std::uint32_t counts_max[gnc::kModeCount] = {};
  std::uint32_t counted[gnc::kModeCount] = {};
  TickNote worst[kWorst] = {};
  double confirmed_at_s = -1.0;  // stuck=N: when the flight confirmed that thruster stuck on
  std::uint32_t over_budget = 0;
  // The 20000-instruction budget in counts (instructions per count from the calibration loop).
  const std::uint32_t budget_counts =
      cal_counts > 0 ? static_cast<std::uint32_t>(20000.0 * cal_counts / (2.0 * kCalIterations))
                     : 0xFFFFFFFFU;

  line.str("  t [s]     |w| [rad/s]  mode      fuel [kg]");
  line.flush();
  double t = 0.0;
  for (std::uint32_t k = 0; k < ticks; ++k) {
    gnc::GncCommands cmd;
    if (k == 0) {
      cmd.has_mode_request = true;
      cmd.mode_request = first_mode;
    }
    const gnc::SensorSample s = sample_of(body, t);
    // The stack is measured on the first tick (mode change), then on every print tick; every other
    // tick is counted for the instruction figures.
    if (k == 0 || (k % print_ticks) == 0) {
      const std::uint32_t used = step_measuring_stack(s, cmd);
      if (k == 0) stack_first = used;
      if (used > stack_max) stack_max = used;
    } else {
      const Snapshot before = snapshot();
      const std::uint32_t c0 = board::counter_now();
      rs_probe_begin();
      g_gnc.step(s, cmd, g_out);
      rs_probe_end();
      const std::uint32_t c = board::counter_elapsed(c0, board::counter_now());
      const auto m = static_cast<std::size_t>(g_gnc.mode());
      if (c > worst[kWorst - 1].counts) {  // keep the kWorst largest, with what the tick did
        TickNote n;
        n.k = k;
        n.counts = c;
        n.mode = static_cast<std::uint8_t>(m);
        n.what = tick_events(before, snapshot());
        std::size_t i = kWorst - 1;
        while (i > 0 && worst[i - 1].counts < c) {
          worst[i] = worst[i - 1];
          --i;
        }
        worst[i] = n;
      }
      counts_total[m] += c;
      counted[m] += 1U;
      if (c > counts_max[m]) counts_max[m] = c;
      if (c > budget_counts) ++over_budget;
    }
    gnc::Vec8 applied = g_out.command.force;
    if (opt.stuck >= 0 && t >= static_cast<double>(opt.onset_s)) {
      // Thruster `stuck` fires u_max whatever is commanded; its partner still answers the command.
      const int c = opt.stuck / 2;
      const double u_max = g_params.rcs.u_max;
      const double asked = applied(c);
      applied(c) = (opt.stuck % 2 == 0) ? u_max - std::fmax(-asked, 0.0) : -u_max + std::fmax(asked, 0.0);
    }
    if (opt.degraded >= 0 && t >= static_cast<double>(opt.onset_s)) {
      // Thruster `degraded` delivers half of its command; its partner is unaffected.
      const int c = opt.degraded / 2;
      if ((opt.degraded % 2 == 0) == (applied(c) > 0.0)) applied(c) *= 0.5;
    }
    for (int c = 0; c < gnc::kChannels; ++c) {  // a closed latch valve: the pod produces nothing
      const auto pod = static_cast<std::size_t>(g_params.rcs.channel_pod[static_cast<std::size_t>(c)]);
      if (!g_out.command.valve_open[pod]) applied(c) = 0.0;
    }
    const gnc::Vec3 torque = b_true * applied;
    if (opt.stuck >= 0 && confirmed_at_s < 0.0 &&
        ((g_gnc.fault_detector().confirmed_on() >> opt.stuck) & 1U) != 0) {
      confirmed_at_s = t;
    }
    if (opt.degraded >= 0 && confirmed_at_s < 0.0 &&
        ((g_gnc.fault_detector().confirmed_degraded() >> opt.degraded) & 1U) != 0) {
      confirmed_at_s = t;
    }
    body.step(dt, torque);
    t += dt;
    if (g_gnc.mode() == gnc::Mode::kHold) {
      reached_hold = true;
    } else {
      always_hold = false;
    }

    if ((k + 1) % print_ticks == 0 || k + 1 == ticks) {
      const double w = body.omega().norm();
      // The despin must make progress at every print while DETUMBLE is active.
      if (g_gnc.mode() == gnc::Mode::kDetumble && w > last_printed_w) monotone = false;
      last_printed_w = w;
      line.fix(t, 1).str("  ").sci(w, 4).str("  ").str(gnc::to_string(g_gnc.mode())).str("  ")
          .fix(g_out.telemetry.fuel_kg, 2);
      line.flush();
    }
  }

  const double w_end = body.omega().norm();
  // Counts -> instructions: the calibration loop executes 2 * kCalIterations instructions.
  const double insn_per_count =
      cal_counts > 0 ? 2.0 * kCalIterations / static_cast<double>(cal_counts) : 0.0;
  line.str("stack: high-water of one Gnc::step ").u32(stack_max).str(" B (first tick ")
      .u32(stack_first).str(" B); whole run ").u32(
          static_cast<std::uint32_t>(board::stack_top() - board::lowest_stack_address_used()))
      .str(" B of ").u32(static_cast<std::uint32_t>(board::stack_top() - board::stack_bottom()))
      .str(" B");
  line.flush();
  line.str("instructions per Gnc::step (SysTick; exact under qemu -icount; calibration ")
      .u32(cal_counts).str(" counts / ").u32(2U * kCalIterations).str(" insns):");
  line.flush();
  for (int m = 0; m < gnc::kModeCount; ++m) {
    if (counted[m] == 0) continue;
    const double mean = static_cast<double>(counts_total[m]) / counted[m];
    line.str("  ").str(gnc::to_string(static_cast<gnc::Mode>(m))).str(": mean ")
        .fix(mean * insn_per_count, 0).str(", max ")
        .fix(counts_max[m] * insn_per_count, 0)
        .str(" over ").u32(counted[m]).str(" ticks");
    line.flush();
  }

  // The largest ticks, with what happened on them (W: an identification window closed, S: the
  // identifier's fault-torque score came out, Z: the fault torque was settled at zero, A: a model
  // was adopted, R: the identifier re-inflated, V: a valve moved, F: the fault detector's best
  // hypothesis or suspicion changed, -: none of these).
  line.str("ticks over the 20000-instruction budget: ").u32(over_budget).str(" of ")
      .u32(ticks);
  line.flush();
  line.str("largest ticks (tick, mode, instructions, events):");
  line.flush();
  for (const TickNote& n : worst) {
    if (n.counts == 0) continue;
    line.str("  ").u32(n.k).str("  ").str(gnc::to_string(static_cast<gnc::Mode>(n.mode)))
        .str("  ").fix(n.counts * insn_per_count, 0).str("  ").str(n.what.text);
    line.flush();
  }

  // Success: |w| never grew between prints, fell well below its initial value, the vehicle never
  // went SAFE, and (goal=hold) DETUMBLE handed over to HOLD. With start=hold: HOLD on every tick.
  const bool fell = w_end < 0.5 * w0;
  const bool safe = g_gnc.mode() == gnc::Mode::kSafe;
  // With stuck=N: the flight also confirmed that thruster stuck on, and nothing else.
  const gnc::FaultDetectorStatus& fdi = g_gnc.fault_detector().status();
  const bool isolated =
      (opt.stuck < 0 || (confirmed_at_s >= 0.0 && fdi.confirmed_off == 0 &&
                         fdi.confirmed_degraded == 0 && fdi.confirmed_on == (1U << opt.stuck))) &&
      (opt.degraded < 0 || (confirmed_at_s >= 0.0 && fdi.confirmed_off == 0 &&
                            fdi.confirmed_on == 0 && fdi.confirmed_degraded == (1U << opt.degraded)));
  const bool ok = isolated && (opt.start_hold ? always_hold
                                              : monotone && fell && !safe &&
                                                    (!opt.require_hold || reached_hold));
  line.str("result: |w| ").sci(w0, 4).str(" -> ").sci(w_end, 4).str(" rad/s, monotone=")
      .str(monotone ? "yes" : "no").str(", hold reached=").str(reached_hold ? "yes" : "no")
      .str(ok ? "  PASS" : "  FAIL");
  line.flush();
  if (opt.stuck >= 0) {  // what the fault detector made of the injected fault
    const gnc::FaultDetectorStatus& st = fdi;
    line.str("fault: thruster ").u32(static_cast<std::uint32_t>(opt.stuck)).str(" stuck on at ")
        .u32(opt.onset_s).str(" s: ");
    if (confirmed_at_s >= 0.0) {
      line.str("confirmed at ").fix(confirmed_at_s, 1).str(" s");
    } else {
      line.str("NOT confirmed");
    }
    line.str(", isolation tests ").u32(st.probes).str(", jet checks ").u32(st.checks)
        .str(", confirmed on/off masks ")
        .u32(st.confirmed_on).str("/").u32(st.confirmed_off);
    line.flush();
  }
  if (opt.degraded >= 0) {
    const gnc::FaultDetector& d = g_gnc.fault_detector();
    line.str("fault: thruster ").u32(static_cast<std::uint32_t>(opt.degraded))
        .str(" at half strength from ").u32(opt.onset_s).str(" s: ");
    if (confirmed_at_s >= 0.0) {
      line.str("confirmed degraded at ").fix(confirmed_at_s, 1).str(" s, factor ")
          .fix(d.strength_factor(opt.degraded), 3);
    } else {
      line.str("NOT confirmed");
    }
    line.str(", jet checks ").u32(fdi.checks).str(", confirmed on/off/degraded masks ")
        .u32(fdi.confirmed_on).str("/").u32(fdi.confirmed_off).str("/").u32(fdi.confirmed_degraded);
    line.flush();
  }
  if (opt.balance_urad_s > 0) {  // (F61) what the channel balance tests did
    line.str("balance tests: ").u32(fdi.balance_tests).str(" started, ")
        .u32(fdi.balance_aborted).str(" dropped, ").u32(fdi.balance_inconclusive)
        .str(" channels inconclusive, ").u32(fdi.balance_confirmations).str(" faults confirmed");
    line.flush();
  }
  return ok ? 0 : 1;
}
