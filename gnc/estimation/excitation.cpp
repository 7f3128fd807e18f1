#include "gnc/estimation/excitation.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

namespace rocksteady::gnc {

namespace {
bool finite_positive(double x) { return std::isfinite(x) && x > 0.0; }
// The cycle +a, -a per body axis with a positive amplitude, in axis order (X3, X8): the number of
// entries written to out.
int axis_cycle(const Vec3& amplitude, Vec3 (&out)[IdentificationExcitation::kDirections]) {
  int n = 0;
  for (int axis = 0; axis < 3; ++axis) {
    if (!(amplitude(axis) > 0.0)) continue;
    for (const double sign : {1.0, -1.0}) {
      out[n] = Vec3::Zero();
      out[n](axis) = sign * amplitude(axis);
      ++n;
    }
  }
  return n;
}
constexpr double kRankTol = 1e-10;   // pivot of M M' (relative to the largest) counted as zero
constexpr double kBoundTol = 1e-9;   // a channel within this fraction of its bound is at the bound
}  // namespace

ExcitationConfigCheck validate(const ExcitationConfig& c) {
  if (!(c.force_n.allFinite() && c.force_n.minCoeff() >= 0.0 && c.force_n.maxCoeff() > 0.0)) {
    return {false, "identification.excitation.force_n", "must be finite, >= 0, one axis > 0"};
  }
  if (!(std::isfinite(c.duration_s) && c.duration_s >= 0.0)) {
    return {false, "identification.excitation.duration_s", "must be >= 0 and finite"};
  }
  if (!(std::isfinite(c.start_after_s) && c.start_after_s >= 0.0)) {
    return {false, "identification.excitation.start_after_s", "must be >= 0 and finite"};
  }
  if (!finite_positive(c.r_sigma_stop_m)) {
    return {false, "identification.excitation.r_sigma_stop_m", "must be positive and finite"};
  }
  if (!(std::isfinite(c.r_sigma_target_m) && c.r_sigma_target_m >= 0.0)) {
    return {false, "identification.excitation.r_sigma_target_m", "must be >= 0 and finite"};
  }
  if (!(c.inertia_torque_nm.allFinite() && c.inertia_torque_nm.minCoeff() >= 0.0)) {
    return {false, "identification.excitation.inertia_torque_nm", "must be finite and >= 0"};
  }
  return {};
}

void IdentificationExcitation::configure(const ExcitationConfig& c) {
  config_ = c;
  n_directions_ = axis_cycle(c.force_n, directions_);      // (X3)
  n_couples_ = axis_cycle(c.inertia_torque_nm, couples_);  // (X8)
  // (X7) Every component of r is seen from the forces normal to it: r_a from the other axes'.
  min_pair_ = 0.0;
  for (int a = 0; a < 3; ++a) {
    double pair = 0.0;
    for (int b = 0; b < 3; ++b) {
      if (b != a) pair += c.force_n(b) * c.force_n(b);
    }
    if (a == 0 || pair < min_pair_) min_pair_ = pair;
  }
  scale_ = 1.0;
}

void IdentificationExcitation::size_to_window_noise(double rho, double window_s) {
  // (X7) (X1) summed over a cycle: an axis a of the n in the cycle gets 1/n of the D/T windows, and
  // the others' forces f_b give r_a the information (D/T)(1/n)(T^2/(4 rho)) sum_{b != a} f_b^2.
  // Set to 1/sigma^2 for the worst-seen component and solved for the common scale s of f.
  scale_ = 1.0;
  const double sigma = config_.r_sigma_target_m;
  const double d = config_.duration_s;
  if (!(sigma > 0.0) || !(d > 0.0) || !(min_pair_ > 0.0) || !(rho > 0.0) || !std::isfinite(rho) ||
      !(window_s > 0.0) || !std::isfinite(window_s)) {
    return;
  }
  const double n = static_cast<double>(n_directions_ / 2);
  const double s2 = 4.0 * n * rho / (d * window_s * sigma * sigma * min_pair_);
  scale_ = s2 < 1.0 ? std::sqrt(s2) : 1.0;
}

void IdentificationExcitation::set_model(const Mat38& b_hat, const RcsLayout& rcs) {
  m_.topRows<3>() = b_hat;
  for (int c = 0; c < kChannels; ++c) m_.block<3, 1>(3, c) = rcs.channel_direction[c];
  stage_ = 0;
  valid_ = false;
}

void IdentificationExcitation::step_model() {
  switch (stage_) {
    case 0:  // G = M M' (6x6)
      g_ = m_ * m_.transpose();
      break;
    case 1: {  // G^-1 (LDLT, fixed size)
      const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(g_);
      const Vec6 d = ldlt.vectorD();
      valid_ = ldlt.info() == Eigen::Success && d.allFinite() && d.minCoeff() > kRankTol * d.maxCoeff();
      g_inv_ = ldlt.solve(Eigen::Matrix<double, 6, 6>::Identity());
      break;
    }
    case 2:  // N = M' G^-1 [0; I3]   (X2), C = M' G^-1 [I3; 0] (X8), and H = G^-1 M for the projector
      n_ = m_.transpose() * g_inv_.rightCols<3>();
      c_ = m_.transpose() * g_inv_.leftCols<3>();
      h_ = g_inv_ * m_;
      break;
    case 3:  // the projector on the kernel of M: P = I - M' G^-1 M
      p_ = Eigen::Matrix<double, kChannels, kChannels>::Identity() - m_.transpose() * h_;
      break;
    case 4: {  // Z: Gram-Schmidt on P's two largest columns (rank 8 - 6 = 2)
      for (int k = 0; k < 2; ++k) {
        int best = 0;
        double best_norm = -1.0;
        for (int j = 0; j < kChannels; ++j) {
          Vec8 v = p_.col(j);
          if (k == 1) v -= z_.col(0) * z_.col(0).dot(v);
          const double nv = v.norm();
          if (nv > best_norm) {
            best_norm = nv;
            best = j;
          }
        }
        Vec8 v = p_.col(best);
        if (k == 1) v -= z_.col(0) * z_.col(0).dot(v);
        if (!(best_norm > 1e-6)) {
          valid_ = false;
          z_.col(k).setZero();
        } else {
          z_.col(k) = v / v.norm();
        }
      }
      break;
    }
    case 5:  // checks: B_hat N = 0, E N = I, B_hat C = I, E C = 0, M Z = 0 (to rounding)
      if (valid_) {
        const double scale = std::max(1.0, m_.cwiseAbs().maxCoeff());
        Eigen::Matrix<double, 6, 3> target = Eigen::Matrix<double, 6, 3>::Zero();
        target.bottomRows<3>().setIdentity();
        Eigen::Matrix<double, 6, 3> target_c = Eigen::Matrix<double, 6, 3>::Zero();
        target_c.topRows<3>().setIdentity();
        valid_ = (m_ * n_ - target).cwiseAbs().maxCoeff() < 1e-9 * scale * (1.0 + n_.cwiseAbs().maxCoeff()) &&
                 (m_ * c_ - target_c).cwiseAbs().maxCoeff() < 1e-9 * scale * (1.0 + c_.cwiseAbs().maxCoeff()) &&
                 (m_ * z_).cwiseAbs().maxCoeff() < 1e-9 * scale;
      }
      break;
    default:
      return;
  }
  ++stage_;
}

bool IdentificationExcitation::wanted(double max_r_sigma, int unobservable,
                                      double identified_s) const {
  return config_.enabled && ready() && n_directions_ > 0 && identified_s >= config_.start_after_s && elapsed_ < config_.duration_s &&
         (unobservable > 0 || !(max_r_sigma <= config_.r_sigma_stop_m));
}

Vec3 IdentificationExcitation::force(std::uint32_t window_index) const {
  if (n_directions_ == 0) return Vec3::Zero();
  // (X3) the window's direction, (X7) at the sized amplitude
  return scale_ * directions_[window_index % static_cast<std::uint32_t>(n_directions_)];
}

bool IdentificationExcitation::inertia_wanted(double identified_s) const {
  return config_.enabled && ready() && n_couples_ > 0 && identified_s < config_.start_after_s;
}

Vec3 IdentificationExcitation::inertia_torque(std::uint32_t window_index) const {
  if (n_couples_ == 0) return Vec3::Zero();
  return couples_[window_index % static_cast<std::uint32_t>(n_couples_)];  // (X8)
}

ExcitationStatus IdentificationExcitation::apply(const Vec3& f, const Vec8& lo, const Vec8& hi,
                                                 double dt, Vec8& u) {
  ExcitationStatus s;
  s.force = f;
  if (!ready()) return s;
  s.active = true;
  elapsed_ += dt;
  fit(n_ * f, lo, hi, u, s);  // (X2), z = 0
  return s;
}

ExcitationStatus IdentificationExcitation::apply_inertia(const Vec3& tau, const Vec8& lo,
                                                         const Vec8& hi, double dt, Vec8& u) {
  ExcitationStatus s;
  s.inertia = true;
  s.torque = tau;
  if (!ready()) return s;
  s.active = true;
  inertia_elapsed_ += dt;
  s.force = m_.bottomRows<3>() * u;  // E u, the allocation's net force
  fit(c_ * tau - n_ * s.force, lo, hi, u, s);  // (X8)
  return s;
}

void IdentificationExcitation::fit(Vec8 du, const Vec8& lo, const Vec8& hi, Vec8& u,
                                   ExcitationStatus& s) const {
  // (X4) A channel already at its bound that du would push further leaves the excitation: the
  // kernel Z moves the null-space force off it (up to two such channels; more leave it to gamma).
  // Z is in the kernel of [B_hat; E], so neither the torque nor the force of du changes.
  int blocked[2] = {-1, -1};
  int nb = 0;
  for (int i = 0; i < kChannels && nb < 2; ++i) {
    const double tol = kBoundTol * std::max(1.0, std::max(hi(i), -lo(i)));
    if ((du(i) > 0.0 && u(i) >= hi(i) - tol) || (du(i) < 0.0 && u(i) <= lo(i) + tol)) {
      blocked[nb++] = i;
    }
  }
  if (nb == 2) {
    Eigen::Matrix2d a;
    a.row(0) = z_.row(blocked[0]);
    a.row(1) = z_.row(blocked[1]);
    const double det = a.determinant();
    if (std::fabs(det) > 1e-6) {
      const Eigen::Vector2d z = -a.inverse() * Eigen::Vector2d(du(blocked[0]), du(blocked[1]));
      du += z_ * z;
      du(blocked[0]) = 0.0;
      du(blocked[1]) = 0.0;
    } else {
      nb = 1;  // the two rows are dependent: remove the first only
    }
  }
  if (nb == 1) {
    const Eigen::RowVector2d a = z_.row(blocked[0]);
    const double na = a.squaredNorm();
    if (na > 1e-12) {
      du -= z_ * (a.transpose() * (du(blocked[0]) / na));
      du(blocked[0]) = 0.0;
    }
  }
  s.blocked = static_cast<std::uint8_t>(nb);
  // (X5) the largest fraction of du that fits every channel's box.
  double gamma = 1.0;
  for (int i = 0; i < kChannels; ++i) {
    if (du(i) > 0.0) gamma = std::min(gamma, std::max(0.0, hi(i) - u(i)) / du(i));
    if (du(i) < 0.0) gamma = std::min(gamma, std::min(0.0, lo(i) - u(i)) / du(i));
  }
  gamma = std::max(0.0, gamma);
  for (int i = 0; i < kChannels; ++i) u(i) = std::min(hi(i), std::max(lo(i), u(i) + gamma * du(i)));
  s.gamma = gamma;
}

}  // namespace rocksteady::gnc
