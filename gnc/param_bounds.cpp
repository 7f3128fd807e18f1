#include "gnc/param_bounds.hpp"

#include <cmath>
#include <cstring>

#include <Eigen/Eigenvalues>

#include "gnc/params.hpp"

namespace rocksteady::gnc {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Every row: the range and why. Numbers are deliberately wide (decades around the study's Table 4
// values and the small vehicles of the tests): they exist to refuse values that switch protection
// or control off, not to tune.
constexpr ParamBound kBounds[] = {
    {"dt", BoundKind::kScalar, 1e-3, 10.0, "s",
     "GNC period: 1 kHz is beyond the sensors' rates, above 10 s the loop cannot follow a body "
     "turning at eps_trans"},
    {"mass_hat.m_sc", BoundKind::kScalar, 1.0, 1e8, "kg",
     "from a cubesat-sized test article to the captured asteroid's spacecraft with margin"},
    {"rcs.u_max", BoundKind::kScalar, 1e-3, 1e4, "N",
     "a thruster channel: 1 mN (cold gas) to 10 kN; 1e300 N made the fuel model meaningless"},
    {"isp", BoundKind::kScalar, 10.0, 1000.0, "s",
     "specific impulse of chemical and cold-gas thrusters (Eq. 54)"},
    {"g0", BoundKind::kScalar, 9.7, 9.9, "m/s^2", "standard gravity (Eq. 54)"},
    // Gains: decay rate of the sliding variable s (Eq. 9): at least 1e-7 1/s (a despin within
    // months; K = 1e-300 gave none), at most the loop rate 1/dt (K = 1e30 fired all thrusters at
    // the smallest error: 9963 kg of fuel).
    {"ntcl.K", BoundKind::kGainRate, 1e-7, 1.0, "N m s", "decay rate of s (Eq. 9)"},
    {"el.K", BoundKind::kGainRate, 1e-7, 1.0, "N m s", "decay rate of s (Eq. 17)"},
    {"feedforward.K", BoundKind::kGainRate, 1e-7, 1.0, "N m s", "decay rate of s"},
    {"integral.K", BoundKind::kGainRate, 1e-7, 1.0, "N m s", "decay rate of s (Eq. 19)"},
    {"adaptive.K", BoundKind::kGainRate, 1e-7, 1.0, "N m s", "decay rate of s (Eq. 34)"},
    {"so3.K", BoundKind::kGainRate, 1e-7, 1.0, "N m s", "decay rate of s (Eq. 37)"},
    {"dpd.K_d", BoundKind::kGainRate, 1e-7, 1.0, "N m s", "rate damping (Eq. 49)"},
    // Bandwidths: a Lambda of 1e-6 1/s converges in weeks; above pi/dt (Nyquist) the discrete loop
    // cannot realise it.
    {"ntcl.Lambda", BoundKind::kBandwidth, 1e-6, kPi, "1/s", "attitude bandwidth (Eq. 9)"},
    {"el.Lambda", BoundKind::kBandwidth, 1e-6, kPi, "1/s", "attitude bandwidth (Eq. 17)"},
    {"feedforward.Lambda", BoundKind::kBandwidth, 1e-6, kPi, "1/s", "attitude bandwidth"},
    {"integral.Lambda", BoundKind::kBandwidth, 1e-6, kPi, "1/s", "attitude bandwidth"},
    {"adaptive.Lambda", BoundKind::kBandwidth, 1e-6, kPi, "1/s", "attitude bandwidth"},
    {"so3.Lambda", BoundKind::kBandwidth, 1e-6, kPi, "1/s", "attitude bandwidth (Eq. 37)"},
    {"integral.K_I", BoundKind::kEigen, 1e-9, 1e9, "N m/rad",
     "integral gain: positive, below the point where the integral alone saturates every thruster"},
    {"integral.integral_limit", BoundKind::kScalar, 1e-6, 1e6, "N m",
     "anti-windup clamp: at most ~100x the torque any RCS here can produce"},
    {"adaptive.Gamma", BoundKind::kScalar, 1e-6, 1e18, "kg^2 m^4 s^-1",
     "adaptation gain (Eq. 34): J ~ 1e8 kg m^2 needs ~1e12; above 1e18 the estimate jumps per tick"},
    {"adaptive.eig_floor_ratio", BoundKind::kScalar, 1e-3, 0.999, "",
     "projection floor (fraction of lambda_min(J_hat0))"},
    {"adaptive.eig_ceiling_ratio", BoundKind::kScalar, 1.001, 1e3, "",
     "projection ceiling (multiple of lambda_max(J_hat0))"},
    {"dpd.k_p", BoundKind::kScalar, 1e-6, 1e6, "",
     "D+PD attitude gain (Eq. 50): positive, finite"},
    {"guidance.omega_switch", BoundKind::kScalar, 1e-6, 0.1, "rad/s",
     "D+PD switch / HOLD threshold (Eq. 51): a rate the gyro resolves, below 6 deg/s"},
    {"guidance.eps_trans", BoundKind::kScalar, 1e-5, 2.0, "rad/s",
     "bound on |omega_d| of a planned trajectory (the study's 0.5 rpm = 0.052 rad/s)"},
    {"guidance.k_qd", BoundKind::kScalar, 1e-9, 10.0, "1/s", "Eqs. (46)-(48) pointing gain"},
    {"guidance.track_reset_period", BoundKind::kScalar, 0.0, 1e7, "s",
     "0: never; at most ~4 months (longer than any plan)"},
    {"guidance.slew", BoundKind::kScalar, 0.0, 1e7, "s",
     "acquisition slew after the plan: 0 = Eqs. (46)-(48); at most ~4 months"},
    {"guidance.slew_ramp", BoundKind::kScalar, 1e-3, 1e7, "s",
     "the slew's acceleration ramps (capped at half the slew)"},
    {"guidance.track_momentum_k", BoundKind::kScalar, 0.0, 10.0, "1/s",
     "momentum tracking's feedback: 0 = the law on the plan's rates; at most the tick's rate"},
    {"estimator.omega_c", BoundKind::kScalar, 1e-5, kPi / 1e-3, "rad/s",
     "filter cutoff (SPEC 6), also below pi/dt (checked by validate)"},
    {"estimator.gyro_max_rate", BoundKind::kScalar, 1e-3, 20.0, "rad/s",
     "a gyro reading above this is rejected: at most a gyro's range (~1000 deg/s)"},
    {"estimator.quat_norm_tolerance", BoundKind::kScalar, 1e-9, 0.5, "",
     "star-tracker |q| deviation accepted; 0.5 would accept garbage"},
    // Configuration-only values (the YAML loader, config/): not in GncParams.
    {"case.duration_s", BoundKind::kScalar, 1e-3, 1e7, "s",
     "simulated run length: up to ~4 months (the study's runs are 1e5 s); 1e300 never ends"},
    {"mode.sensor_timeout", BoundKind::kScalar, 1e-3, 60.0, "s",
     "no valid sample this long -> SAFE: thrusters firing open loop for more than a minute is "
     "unsafe (1e30 s kept them firing 8 s with no sensor at all and never stopped)"},
};
constexpr int kBoundCount = static_cast<int>(sizeof kBounds / sizeof kBounds[0]);

Check out_of_range(const ParamBound& b) {
  return Check{false, b.name, b.why};
}

bool scalar_ok(const ParamBound& b, double v) {
  return std::isfinite(v) && v >= b.lo && v <= b.hi;
}

// Eigenvalues of the symmetric part (ascending).
Vec3 eigenvalues(const Mat3& m) {
  const Mat3 s = 0.5 * (m + m.transpose());
  Eigen::SelfAdjointEigenSolver<Mat3> es(s, Eigen::EigenvaluesOnly);
  return es.eigenvalues();
}

}  // namespace

const ParamBound* param_bounds(int& count) {
  count = kBoundCount;
  return kBounds;
}

const ParamBound* find_param_bound(const char* name) {
  for (const ParamBound& b : kBounds) {
    if (std::strcmp(b.name, name) == 0) return &b;
  }
  return nullptr;
}

bool within_bound(const char* name, double value) {
  const ParamBound* b = find_param_bound(name);
  if (b == nullptr || b->kind != BoundKind::kScalar) return true;
  return scalar_ok(*b, value);
}

Check check_bounds(const GncParams& p) {
  const Mat3 j_tot = total_inertia(p.mass_hat);
  const Vec3 ej = eigenvalues(j_tot);
  const double j_min = ej(0);
  const double j_max = ej(2);
  for (const ParamBound& b : kBounds) {
    const char* n = b.name;
    auto scalar = [&](double v) { return scalar_ok(b, v); };
    auto eig = [&](const Mat3& m) {
      if (!m.allFinite()) return false;
      const Vec3 e = eigenvalues(m);
      const double hi = b.kind == BoundKind::kBandwidth ? b.hi / p.dt : b.hi;
      return e(0) >= b.lo && e(2) <= hi;
    };
    auto gain = [&](const Mat3& k) {
      if (!k.allFinite() || !(j_min > 0.0)) return false;
      const Vec3 e = eigenvalues(k);
      return e(0) / j_max >= b.lo && e(2) / j_min <= b.hi / p.dt;
    };
    bool ok = true;
    if (!std::strcmp(n, "dt")) ok = scalar(p.dt);
    else if (!std::strcmp(n, "mass_hat.m_sc")) ok = scalar(p.mass_hat.m_sc);
    else if (!std::strcmp(n, "rcs.u_max")) ok = scalar(p.rcs.u_max);
    else if (!std::strcmp(n, "isp")) ok = scalar(p.isp_s);
    else if (!std::strcmp(n, "g0")) ok = scalar(p.g0);
    else if (!std::strcmp(n, "ntcl.K")) ok = gain(p.ntcl.k);
    else if (!std::strcmp(n, "el.K")) ok = gain(p.el.k);
    else if (!std::strcmp(n, "feedforward.K")) ok = gain(p.feedforward.k);
    else if (!std::strcmp(n, "integral.K")) ok = gain(p.integral.k);
    else if (!std::strcmp(n, "adaptive.K")) ok = gain(p.adaptive.k);
    else if (!std::strcmp(n, "so3.K")) ok = gain(p.so3.k);
    else if (!std::strcmp(n, "dpd.K_d")) ok = gain(p.dpd.k_d);
    else if (!std::strcmp(n, "ntcl.Lambda")) ok = eig(p.ntcl.lambda);
    else if (!std::strcmp(n, "el.Lambda")) ok = eig(p.el.lambda);
    else if (!std::strcmp(n, "feedforward.Lambda")) ok = eig(p.feedforward.lambda);
    else if (!std::strcmp(n, "integral.Lambda")) ok = eig(p.integral.lambda);
    else if (!std::strcmp(n, "adaptive.Lambda")) ok = eig(p.adaptive.lambda);
    else if (!std::strcmp(n, "so3.Lambda")) ok = eig(p.so3.lambda);
    else if (!std::strcmp(n, "integral.K_I")) ok = eig(p.integral.k_i);
    else if (!std::strcmp(n, "integral.integral_limit")) ok = scalar(p.integral.integral_limit_nm);
    else if (!std::strcmp(n, "adaptive.Gamma")) ok = scalar(p.adaptive.gamma);
    else if (!std::strcmp(n, "adaptive.eig_floor_ratio")) ok = scalar(p.adaptive.eig_floor_ratio);
    else if (!std::strcmp(n, "adaptive.eig_ceiling_ratio")) ok = scalar(p.adaptive.eig_ceiling_ratio);
    else if (!std::strcmp(n, "dpd.k_p")) ok = scalar(p.dpd.k_p);
    else if (!std::strcmp(n, "guidance.omega_switch")) ok = scalar(p.guidance.omega_switch);
    else if (!std::strcmp(n, "guidance.eps_trans")) ok = scalar(p.guidance.eps_trans);
    else if (!std::strcmp(n, "guidance.k_qd")) ok = scalar(p.guidance.k_qd);
    else if (!std::strcmp(n, "guidance.track_reset_period")) ok = scalar(p.guidance.track_reset_period_s);
    else if (!std::strcmp(n, "guidance.slew")) ok = scalar(p.guidance.slew_s);
    else if (!std::strcmp(n, "guidance.slew_ramp")) ok = scalar(p.guidance.slew_ramp_s);
    else if (!std::strcmp(n, "guidance.track_momentum_k")) ok = scalar(p.guidance.track_momentum_k);
    else if (!std::strcmp(n, "estimator.omega_c")) ok = scalar(p.estimator.omega_c);
    else if (!std::strcmp(n, "estimator.gyro_max_rate")) ok = scalar(p.estimator.gyro_max_rate);
    else if (!std::strcmp(n, "estimator.quat_norm_tolerance")) ok = scalar(p.estimator.quat_norm_tolerance);
    else if (!std::strcmp(n, "mode.sensor_timeout")) ok = scalar(p.mode.sensor_timeout_s);
    if (!ok) return out_of_range(b);
  }
  return Check{};
}

}  // namespace rocksteady::gnc
