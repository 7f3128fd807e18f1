// Measurements for the estimation design note (gnc/estimation/README.md): identification errors
// on the study's cases flown open-loop by a simple D+PD law (Eqs. 49-50) with the pseudoinverse
// allocation (Eq. 53) on the flight's estimates, and the MEKF's HOLD attitude error against the
// Farrenkopf steady state. Ground tool: prints a table, asserts nothing.
//
//   estimation_study CONFIG_DIR
//   estimation_study CONFIG_DIR excitation [FORCE_N [DURATION_S [R_SIGMA_STOP_M [R_SIGMA_TARGET_M
//                    [INERTIA_TORQUE_NM]]]]]
//     the seven cases with the flight's identifier settings, without and with the identification
//     excitation (README §I.6), and the fuel each run spent
#include <cmath>
#include <exception>
#include <cstdio>
#include <string>

#include <Eigen/Dense>

#include "estimation_truth.hpp"
#include "gnc/estimation/excitation.hpp"
#include "gnc/estimation/identifier.hpp"
#include "gnc/estimation/mekf.hpp"
#include "gnc/estimation/state_filter.hpp"
#include "gnc/math/rotation.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "ground/config/config.hpp"
#include "ground/plant/plant.hpp"

namespace {

using namespace rocksteady;
using gnc::Mat3;
using gnc::Vec3;
using gnc::Vec4;
using gnc::Vec8;

// Eq. (53) with the SPEC §4 rescaling.
Vec8 allocate(const gnc::Mat38& b, const Vec3& u_c, double u_max) {
  const Vec8 u = b.transpose() * (b * b.transpose()).ldlt().solve(u_c);
  const double m = u.cwiseAbs().maxCoeff();
  return m > u_max ? Vec8(u * (u_max / m)) : u;
}

// D+PD, Eqs. (49)-(50), target q_final = 0.
Vec3 dpd(const Vec3& omega, const Vec4& beta, bool& pd) {
  if (omega.norm() <= 5e-4) pd = true;
  const Vec4 b = beta.w() < 0 ? Vec4(-beta) : beta;
  return pd ? Vec3(-10.0 * b.head<3>() - 1e4 * omega) : Vec3(-1e4 * omega);
}

bool g_estimate_bias = false;  // "estimate_bias" on the command line: b estimated, not considered

struct Errors {
  double j, r, k, j_sigma_rel, r_sigma, nees_j, nees_r, r_sigma_max;
};

struct Outcome {
  Errors e[5];
  double fuel_kg{0.0};
  double excitation_s{0.0};
  double gamma_mean{0.0};
  double scale_mean{0.0};  // mean amplitude scale of (X7) over the excited ticks
};

// window_s <= 0: the flight's window for the case (gnc.yaml, quiet or noisy sensors).
// gyro_bias > 0: the plant's gyro gets a constant bias of that norm.
// excitation: the identification excitation's settings (README §I.6); off unless enabled.
Outcome identification(const std::string& dir, int case_number, gnc::IdentifierMode mode,
                       double window_s, double k_prior_sigma, double gyro_bias = 0.0,
                       const gnc::ExcitationConfig& excitation = gnc::ExcitationConfig{},
                       bool print = true) {
  Outcome out;
  config::RunSetup run =
      config::load_run(dir + "/mission.yaml", dir + "/gnc.yaml",
                       dir + "/cases/case" + std::to_string(case_number) + ".yaml");
  run.truth.sensors.gyro_bias = Vec3(1.0, -0.5, 0.3).normalized() * gyro_bias;
  if (window_s <= 0.0) window_s = run.flight.identification.config.window_s;
  plant::Plant plant(run.truth);
  const Mat3 j_true = plant.inertia();
  const Vec3 r_true = run.truth.mass.r_so_bcm;
  const Mat3 j_hat = gnc::total_inertia(run.flight.mass_hat);
  const gnc::Mat38 b_hat = gnc::torque_matrix(run.flight.rcs, run.flight.mass_hat.r_so_bcm);
  gnc::IdentifierConfig c;
  c.mode = mode;
  c.dt = run.flight.dt;
  c.window_s = window_s;
  c.rcs = run.flight.rcs;
  c.j0 = j_hat;
  c.r0 = run.flight.mass_hat.r_so_bcm;
  c.j_prior_sigma = 1e7;
  c.r_prior_sigma = 1.0;
  c.k_prior_sigma = k_prior_sigma;
  c.gyro_sigma = std::sqrt(run.truth.sensors.gyro_psd / run.truth.sensors.period_s);
  // The flight's bias prior and innovation gate (gnc.yaml, README I17/I18).
  c.gyro_bias_sigma = run.flight.identification.config.gyro_bias_sigma;
  c.gate_chi2 = run.flight.identification.config.gate_chi2;
  c.second_order_noise = run.flight.identification.config.second_order_noise;
  c.gate_reinflate_after = run.flight.identification.config.gate_reinflate_after;
  c.gyro_bias_estimated = run.flight.identification.config.gyro_bias_estimated || g_estimate_bias;
  const gnc::IdentifierConfigCheck check = gnc::validate(c);
  if (!check.ok) {
    std::printf("bad identifier config: %s: %s\n", check.field, check.reason);
    return out;
  }
  gnc::IdentificationExcitation ex;
  ex.configure(excitation);
  ex.set_model(b_hat, run.flight.rcs);
  for (int i = 0; i < gnc::IdentificationExcitation::kModelStages; ++i) ex.step_model();
  const Vec8 lo = Vec8::Constant(-run.flight.rcs.u_max), hi = Vec8::Constant(run.flight.rcs.u_max);
  double gamma_sum = 0.0;
  double scale_sum = 0.0;
  long excited_ticks = 0;
  gnc::Identifier id;
  id.configure(c);
  Vec8 previous = Vec8::Zero();
  bool pd = false;
  const double marks[] = {60.0, 300.0, 600.0, 1000.0, 3000.0};
  constexpr int kMarks = 5;
  Errors* e = out.e;
  int m = 0;
  const int ticks = static_cast<int>(std::lround(3000.0 / c.dt));
  for (int k = 0; k <= ticks; ++k) {
    const hal::RawSensors s = plant.read_sensors();
    gnc::IdentifierInput in;
    in.omega = s.gyro.rate;
    in.omega_valid = true;
    in.force = previous;
    id.update(in);
    const double t = k * c.dt;
    if (m < kMarks && t >= marks[m] - 1e-9) {
      const gnc::IdentifierEstimate& est = id.estimate();
      e[m].j = (est.j - j_true).norm() / j_true.norm();
      e[m].r = (est.r - r_true).norm();
      e[m].k = (est.k - run.truth.thruster_strength).cwiseAbs().maxCoeff();
      e[m].j_sigma_rel = est.j_sigma.norm() / j_true.norm();
      e[m].r_sigma = est.r_sigma.norm();
      const gnc::Vec6 da = gnc::inertia_params(est.j) - gnc::inertia_params(j_true);
      const Vec3 dr = est.r - r_true;
      e[m].nees_j = da.dot(id.inertia_covariance().ldlt().solve(da));
      e[m].nees_r = dr.dot(id.offset_covariance().ldlt().solve(dr));
      e[m].r_sigma_max = est.r_sigma.maxCoeff();
      ++m;
    }
    Vec8 u = allocate(b_hat, dpd(s.gyro.rate, s.star.quat, pd), run.flight.rcs.u_max);
    const double identified_s = static_cast<double>(id.counters().windows) * c.window_s;
    if (ex.inertia_wanted(identified_s)) {  // (X8) the inertia phase first
      const gnc::ExcitationStatus xs =
          ex.apply_inertia(ex.inertia_torque(id.counters().windows), lo, hi, c.dt, u);
      gamma_sum += xs.gamma;
      ++excited_ticks;
    } else if (ex.wanted(id.estimate().r_sigma.maxCoeff(), id.observability().offset_unobservable,
                  identified_s)) {
      ex.size_to_window_noise(id.latched_window_noise(), c.window_s);  // (X7)
      const gnc::ExcitationStatus xs = ex.apply(ex.force(id.counters().windows), lo, hi, c.dt, u);
      scale_sum += ex.amplitude_scale();
      gamma_sum += xs.gamma;
      ++excited_ticks;
    }
    plant.advance(u, true);
    previous = plant.applied_force();
    out.fuel_kg += gnc::fuel_rate(previous, run.flight.isp_s, run.flight.g0) * c.dt;
  }
  out.excitation_s = ex.elapsed();
  out.gamma_mean = excited_ticks > 0 ? gamma_sum / static_cast<double>(excited_ticks) : 0.0;
  out.scale_mean = excited_ticks > 0 ? scale_sum / static_cast<double>(excited_ticks) : 0.0;
  if (!print) return out;
  std::printf("case %d %-10s T=%2.0f s k0 1s %.2f bias %.0e |", case_number,
              mode == gnc::IdentifierMode::kJoint ? "joint" : "concurrent", window_s, k_prior_sigma,
              gyro_bias);
  for (int i = 0; i < kMarks; ++i) {
    std::printf(" %5.0fs: J %.2e (1s %.1e) r %.3f m (1s %.3f) k %.3f NEES %.1f/%.1f |", marks[i],
                e[i].j, e[i].j_sigma_rel, e[i].r, e[i].r_sigma, e[i].k, e[i].nees_j, e[i].nees_r);
  }
  std::printf(" r unobs %d, refused %u, gated %u\n", id.observability().offset_unobservable,
              id.counters().inertia_refused, id.counters().windows_gated);
  return out;
}

// The seven cases without and with the excitation: markdown rows for the design note.
void excitation_table(const std::string& dir, const gnc::ExcitationConfig& x) {
  std::printf("excitation F (%.0f, %.0f, %.0f) N, after %.0f s, at most %.0f s, stop at r 1s %.3f m, "
              "sized for r 1s %.3f m (0: not sized); before it the inertia phase (X8) at (%.0f, %.0f, %.0f) N m%s\n",
              x.force_n(0), x.force_n(1), x.force_n(2), x.start_after_s, x.duration_s, x.r_sigma_stop_m,
              x.r_sigma_target_m, x.inertia_torque_nm(0), x.inertia_torque_nm(1), x.inertia_torque_nm(2),
              g_estimate_bias ? ", gyro bias estimated" : "");
  std::printf("| case | excitation | 60 s | 300 s | 600 s | 1000 s | 3000 s | fuel 3000 s (kg) | excited (s) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (int cs = 1; cs <= 7; ++cs) {
    gnc::ExcitationConfig off = x;
    off.enabled = false;
    const Outcome a = identification(dir, cs, gnc::IdentifierMode::kJoint, 0.0, 0.01, 0.0, off, false);
    const Outcome b = identification(dir, cs, gnc::IdentifierMode::kJoint, 0.0, 0.01, 0.0, x, false);
    for (const Outcome* o : {&a, &b}) {
      std::printf("| %d | %s |", cs, o == &a ? "off" : "on");
      for (const Errors& e : o->e) {
        std::printf(" %.1e · %.3f (%.3f) · %.3f |", e.j, e.r, e.r_sigma_max, e.k);
      }
      std::printf(" %.2f | %.0f (gamma %.2f, scale %.3f) |\n", o->fuel_kg, o->excitation_s, o->gamma_mean,
                  o->scale_mean);
    }
    std::printf("| %d | cost | | | | | | %+.2f | |\n", cs, b.fuel_kg - a.fuel_kg);
    std::fflush(stdout);
  }
}

void hold(const std::string& dir, int case_number, double gyro_bias, double bias_rw) {
  config::RunSetup run =
      config::load_run(dir + "/mission.yaml", dir + "/gnc.yaml",
                       dir + "/cases/case" + std::to_string(case_number) + ".yaml");
  run.truth.omega0.setZero();  // HOLD: at rest at the initial attitude
  run.truth.sensors.gyro_bias = Vec3(1.0, -0.5, 0.3).normalized() * gyro_bias;
  run.truth.sensors.gyro_bias_rw = bias_rw;
  plant::Plant plant(run.truth);
  const double ts = run.truth.sensors.period_s;
  gnc::MekfConfig mc;
  mc.dt = run.flight.dt;
  mc.gyro_arw = std::sqrt(run.truth.sensors.gyro_psd);
  mc.gyro_bias_rw = bias_rw > 0.0 ? bias_rw : 1e-10;
  mc.star_sigma = 4.0 * std::sqrt(run.truth.sensors.star_psd / ts);  // dtheta = 4 dq
  mc.init_bias_sigma = gyro_bias > 0.0 ? 3.0 * gyro_bias : 1e-4;
  gnc::Mekf mekf;
  mekf.configure(mc);
  // The same MEKF with the rate stage (M8) at the SPEC §6 filter's cutoff.
  gnc::MekfConfig mc_stage = mc;
  mc_stage.rate_cutoff = run.flight.estimator.omega_c;
  gnc::Mekf staged;
  staged.configure(mc_stage);
  staged.set_rate_model(gnc::total_inertia(run.flight.mass_hat));
  gnc::StateFilter spec;
  gnc::EstimatorParams ep;
  ep.kind = gnc::EstimatorKind::kFilter;
  spec.configure(ep, gnc::total_inertia(run.flight.mass_hat), run.flight.dt);
  double sq_m = 0.0, sq_s = 0.0, max_m = 0.0, sq_wm = 0.0, sq_ws = 0.0, sq_wstage = 0.0;
  int n = 0;
  double b_err_30min = 0.0;
  const int ticks = static_cast<int>(std::lround(4.0 * 3600.0 / run.flight.dt));
  for (int k = 0; k <= ticks; ++k) {
    const hal::RawSensors s = plant.read_sensors();
    gnc::MekfInput mi;
    mi.t = s.t;
    mi.gyro_rate = s.gyro.rate;
    mi.gyro_valid = true;
    mi.star_quat = s.star.quat;
    mi.star_valid = true;
    mekf.update(mi);
    staged.update(mi);  // at rest, no torque commanded
    gnc::Measurement sm;
    sm.omega = s.gyro.rate;
    sm.q = gnc::mrp::from_quaternion(s.star.quat);
    sm.omega_valid = sm.q_valid = true;
    spec.update(sm, Vec3::Zero());
    const double t = k * run.flight.dt;
    if (std::fabs(t - 1800.0) < 1e-6) {
      b_err_30min = (plant.gyro_bias() - mekf.bias()).cwiseAbs().maxCoeff();
    }
    if (t >= 1800.0 && spec.initialised()) {
      const Vec3 em = test::attitude_error(mekf.quaternion(), plant.beta());
      const Vec3 es = test::attitude_error(gnc::mrp::to_quaternion(spec.q()), plant.beta());
      sq_m += em.squaredNorm();
      sq_s += es.squaredNorm();
      max_m = std::fmax(max_m, em.cwiseAbs().maxCoeff());
      sq_wm += (mekf.omega() - plant.omega()).squaredNorm();
      sq_ws += (spec.omega() - plant.omega()).squaredNorm();
      sq_wstage += (staged.omega() - plant.omega()).squaredNorm();
      ++n;
    }
    plant.advance(Vec8::Zero(), false);
  }
  const double analytic =
      test::farrenkopf_post_update_sigma(mc.gyro_arw, mc.gyro_bias_rw, mc.star_sigma, mc.dt);
  std::printf(
      "case %d HOLD bias %.1e rw %.1e | MEKF attitude sigma %.3e rad (max %.2e), Farrenkopf %.3e "
      "(ratio %.3f); rate RMS %.2e rad/s, with the rate stage %.2e | SPEC 6 filter attitude sigma %.3e, rate RMS %.2e | bias "
      "error at 30 min %.2e rad/s = %.2f x its steady-state sigma %.2e\n",
      case_number, gyro_bias, bias_rw, std::sqrt(sq_m / (3.0 * n)), max_m, analytic,
      std::sqrt(sq_m / (3.0 * n)) / analytic, std::sqrt(sq_wm / (3.0 * n)),
      std::sqrt(sq_wstage / (3.0 * n)),
      std::sqrt(sq_s / (3.0 * n)), std::sqrt(sq_ws / (3.0 * n)), b_err_30min,
      b_err_30min / mekf.bias_sigma().maxCoeff(), mekf.bias_sigma().maxCoeff());
}

int run(int argc, char** argv) {
  if (argc > 2 && std::string(argv[argc - 1]) == "estimate_bias") {
    g_estimate_bias = true;
    --argc;
  }
  if (argc < 2 || (argc > 2 && std::string(argv[2]) != "excitation") || argc > 8) {
    std::fprintf(stderr,
                 "usage: %s CONFIG_DIR [excitation [FORCE_N [DURATION_S [R_SIGMA_STOP_M [R_SIGMA_TARGET_M "
                 "[INERTIA_TORQUE_NM]]]]]]\n",
                 argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  if (argc > 2) {
    // The flight's excitation settings (gnc.yaml), then the command line's.
    gnc::ExcitationConfig x =
        config::load_run(dir + "/mission.yaml", dir + "/gnc.yaml", dir + "/cases/case1.yaml")
            .flight.identification.excitation;
    x.enabled = true;
    if (argc > 3) {  // "F" or "Fx,Fy,Fz"
      const std::string a = argv[3];
      const std::size_t c1 = a.find(',');
      if (c1 == std::string::npos) {
        x.force_n = Vec3::Constant(std::stod(a));
      } else {
        const std::size_t c2 = a.find(',', c1 + 1);
        x.force_n = Vec3(std::stod(a.substr(0, c1)), std::stod(a.substr(c1 + 1, c2 - c1 - 1)),
                         std::stod(a.substr(c2 + 1)));
      }
    }
    if (argc > 4) x.duration_s = std::stod(argv[4]);
    if (argc > 5) x.r_sigma_stop_m = std::stod(argv[5]);
    if (argc > 6) x.r_sigma_target_m = std::stod(argv[6]);
    if (argc > 7) x.inertia_torque_nm = Vec3::Constant(std::stod(argv[7]));  // (X8)
    const gnc::ExcitationConfigCheck xc = gnc::validate(x);
    if (!xc.ok) {
      std::fprintf(stderr, "bad excitation: %s: %s\n", xc.field, xc.reason);
      return 2;
    }
    excitation_table(dir, x);
    return 0;
  }
  for (int cs = 1; cs <= 7; ++cs) {
    identification(dir, cs, gnc::IdentifierMode::kJoint, 0.0, 0.01);  // the flight's window
  }
  for (int cs : {1, 4, 5, 7}) {
    identification(dir, cs, gnc::IdentifierMode::kJoint, 20.0, 0.05);
    identification(dir, cs, gnc::IdentifierMode::kJoint, 20.0, 0.01);
    identification(dir, cs, gnc::IdentifierMode::kJoint, 60.0, 0.01);
    identification(dir, cs, gnc::IdentifierMode::kConcurrent, 20.0, 0.01);
  }
  for (int cs : {5, 7}) identification(dir, cs, gnc::IdentifierMode::kJoint, 0.0, 0.01, 5e-5);
  for (int cs : {5, 6, 7}) hold(dir, cs, 0.0, 0.0);
  hold(dir, 5, 5e-5, 0.0);
  hold(dir, 5, 5e-5, 1e-9);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // A bad configuration directory or number is reported, not thrown out of main.
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "estimation_study: %s\n", e.what());
    return 2;
  }
}
