// Measurements for the estimation design note (gnc/estimation/README.md): identification errors
// on the study's cases flown open-loop by a simple D+PD law (Eqs. 49-50) with the pseudoinverse
// allocation (Eq. 53) on the flight's estimates, and the MEKF's HOLD attitude error against the
// Farrenkopf steady state. Ground tool: prints a table, asserts nothing.
//
//   estimation_study CONFIG_DIR
#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Dense>

#include "estimation_truth.hpp"
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

struct Errors {
  double j, r, k, j_sigma_rel, r_sigma, nees_j, nees_r;
};

// window_s <= 0: the flight's window for the case (gnc.yaml, quiet or noisy sensors).
// gyro_bias > 0: the plant's gyro gets a constant bias of that norm.
void identification(const std::string& dir, int case_number, gnc::IdentifierMode mode,
                    double window_s, double k_prior_sigma, double gyro_bias = 0.0) {
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
  const gnc::IdentifierConfigCheck check = gnc::validate(c);
  if (!check.ok) {
    std::printf("bad identifier config: %s: %s\n", check.field, check.reason);
    return;
  }
  gnc::Identifier id;
  id.configure(c);
  Vec8 previous = Vec8::Zero();
  bool pd = false;
  const double marks[] = {60.0, 300.0, 600.0, 1000.0, 3000.0};
  constexpr int kMarks = 5;
  Errors e[kMarks];
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
      ++m;
    }
    const Vec8 u = allocate(b_hat, dpd(s.gyro.rate, s.star.quat, pd), run.flight.rcs.u_max);
    plant.advance(u, true);
    previous = plant.applied_force();
  }
  std::printf("case %d %-10s T=%2.0f s k0 1s %.2f bias %.0e |", case_number,
              mode == gnc::IdentifierMode::kJoint ? "joint" : "concurrent", window_s, k_prior_sigma,
              gyro_bias);
  for (int i = 0; i < kMarks; ++i) {
    std::printf(" %5.0fs: J %.2e (1s %.1e) r %.3f m (1s %.3f) k %.3f NEES %.1f/%.1f |", marks[i],
                e[i].j, e[i].j_sigma_rel, e[i].r, e[i].r_sigma, e[i].k, e[i].nees_j, e[i].nees_r);
  }
  std::printf(" r unobs %d, refused %u, gated %u\n", id.observability().offset_unobservable,
              id.counters().inertia_refused, id.counters().windows_gated);
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

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CONFIG_DIR\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
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
