#include "ground/planner/transcription.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "gnc/math/rotation.hpp"

namespace rocksteady::ground::planner {

using gnc::skew;  // S(v), the flight core's one cross-product matrix

HermiteSimpsonNlp::HermiteSimpsonNlp(const TranscriptionModel& model)
    : model_(model), nodes_(model.nodes), points_(2 * model.nodes - 1) {
  if (model.nodes < 2) throw std::invalid_argument("transcription needs at least 2 nodes");
  if (!(model.t_final_min > 0.0) || !(model.t_final_max >= model.t_final_min)) {
    throw std::invalid_argument("final-time bounds must satisfy 0 < t_final_min <= t_final_max");
  }
  if (!(model.u_max > 0.0) || !(model.eps_trans > 0.0)) {
    throw std::invalid_argument("u_max and eps_trans must be positive");
  }
  // Scaling [Rocksteady choice]: rates in units of eps_trans (|w| <= 1), time in units of the
  // middle of the final-time range, controls in units of u_max (p, n in [0, 1]).
  omega_scale_ = model.eps_trans;
  t_scale_ = 0.5 * (model.t_final_min + model.t_final_max);
  if (model.grid.empty()) {
    s_.resize(nodes_);
    for (int k = 0; k < nodes_; ++k) s_[k] = static_cast<double>(k) / (nodes_ - 1);
    s_.back() = 1.0;
  } else {
    if (static_cast<int>(model.grid.size()) != nodes_ || model.grid.front() != 0.0 ||
        model.grid.back() != 1.0) {
      throw std::invalid_argument("grid must hold N positions from 0 to 1");
    }
    for (int k = 0; k + 1 < nodes_; ++k) {
      if (!(model.grid[k + 1] > model.grid[k])) {
        throw std::invalid_argument("grid positions must increase strictly");
      }
    }
    s_ = model.grid;
  }
  c_.resize(nodes_ - 1);
  weights_.assign(points_, 0.0);
  for (int k = 0; k + 1 < nodes_; ++k) {
    const double ds = s_[k + 1] - s_[k];
    c_[k] = t_scale_ * ds;
    weights_[2 * k] += ds / 6.0;  // Simpson on interval k
    weights_[2 * k + 1] += 4.0 * ds / 6.0;
    weights_[2 * k + 2] += ds / 6.0;
  }
  j_inv_ = model.j_hat.inverse();
  a_ = model.u_max * j_inv_ * model.b_hat / omega_scale_;

  // Defects, interval by interval (see header).
  for (int k = 0; k + 1 < nodes_; ++k) {
    const int a = 2 * k;
    const int m = 2 * k + 1;
    const int b = 2 * k + 2;
    defects_.push_back({{a, -0.5, -1.0 / 8.0}, {m, 1.0, 0.0}, {b, -0.5, 1.0 / 8.0}});
    defects_.push_back({{a, -1.0, -1.0 / 6.0}, {m, 0.0, -4.0 / 6.0}, {b, 1.0, -1.0 / 6.0}});
  }

  // Jacobian pattern.
  for (std::size_t d = 0; d < defects_.size(); ++d) {
    const int row0 = 3 * static_cast<int>(d);
    for (const DefectTerm& term : defects_[d]) {
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
          jac_.rows.push_back(row0 + r);
          jac_.cols.push_back(w_index(term.point) + c);
        }
      }
      if (term.beta == 0.0) continue;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 8; ++c) {
          jac_.rows.push_back(row0 + r);
          jac_.cols.push_back(p_index(term.point) + c);
        }
        for (int c = 0; c < 8; ++c) {
          jac_.rows.push_back(row0 + r);
          jac_.cols.push_back(n_index(term.point) + c);
        }
      }
    }
    for (int r = 0; r < 3; ++r) {
      jac_.rows.push_back(row0 + r);
      jac_.cols.push_back(tau_index());
    }
  }
  const int path0 = 3 * static_cast<int>(defects_.size());
  for (int j = 1; j + 1 < points_; ++j) {
    for (int c = 0; c < 3; ++c) {
      jac_.rows.push_back(path0 + j - 1);
      jac_.cols.push_back(w_index(j) + c);
    }
  }

  // Hessian pattern (lower triangle): per point, the 3x3 rate block and the tau row.
  for (int j = 0; j < points_; ++j) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c <= r; ++c) {
        hess_.rows.push_back(w_index(j) + r);
        hess_.cols.push_back(w_index(j) + c);
      }
    }
    for (int c = 0; c < 3; ++c) {
      hess_.rows.push_back(tau_index());
      hess_.cols.push_back(w_index(j) + c);
    }
    for (int c = 0; c < 16; ++c) {
      hess_.rows.push_back(tau_index());
      hess_.cols.push_back(p_index(j) + c);  // p then n: contiguous
    }
  }
}

Vec3 HermiteSimpsonNlp::g_scaled(const Vec3& w) const {
  const Vec3 jw = model_.j_hat * w;
  return omega_scale_ * j_inv_ * jw.cross(w);  // Eq. (41), gyroscopic part
}

Mat3 HermiteSimpsonNlp::g_scaled_jacobian(const Vec3& w) const {
  // d/dw [(J w) x w] = S(J w) - S(w) J
  return omega_scale_ * j_inv_ * (skew(model_.j_hat * w) - skew(w) * model_.j_hat);
}

Mat3 HermiteSimpsonNlp::g_scaled_hessian(const Vec3& lambda) const {
  // lambda' J^-1 ((J w) x w) = w' S(mu) J w with mu = J^-T lambda; Hessian S(mu) J - J S(mu).
  const Vec3 mu = j_inv_.transpose() * lambda;
  const Mat3 s = skew(mu);
  return omega_scale_ * (s * model_.j_hat - model_.j_hat * s);
}

Vec3 HermiteSimpsonNlp::rhs(const double* x, int j) const {
  const Eigen::Map<const Vec3> w(x + w_index(j));
  const Eigen::Map<const Vec8> p(x + p_index(j));
  const Eigen::Map<const Vec8> n(x + n_index(j));
  return g_scaled(w) + a_ * (p - n);
}

double HermiteSimpsonNlp::point_fraction(int j) const {
  if (j % 2 == 0) return s_[j / 2];
  return 0.5 * (s_[j / 2] + s_[j / 2 + 1]);
}

void HermiteSimpsonNlp::bounds(std::vector<double>& x_lo, std::vector<double>& x_hi,
                               std::vector<double>& g_lo, std::vector<double>& g_hi) const {
  const int n = num_variables();
  x_lo.assign(n, 0.0);
  x_hi.assign(n, 1.0);  // p, n in [0, 1]: |u_i| <= u_max, Eq. (43)
  const double w_bound = model_.eps_trans / omega_scale_;
  for (int j = 0; j < points_; ++j) {
    for (int c = 0; c < 3; ++c) {
      x_lo[w_index(j) + c] = -w_bound;  // implied by the norm bound; helps the solver
      x_hi[w_index(j) + c] = w_bound;
    }
  }
  const Vec3 w0 = model_.omega_init / omega_scale_;
  for (int c = 0; c < 3; ++c) {
    x_lo[w_index(0) + c] = w0[c];  // omega_d(0) = omega_init
    x_hi[w_index(0) + c] = w0[c];
    x_lo[w_index(points_ - 1) + c] = 0.0;  // omega_d(t_final) = 0
    x_hi[w_index(points_ - 1) + c] = 0.0;
  }
  if (model_.rest_at_end) {
    for (int c = 0; c < 8; ++c) {
      x_hi[p_index(points_ - 1) + c] = 0.0;  // u_d(t_final) = 0
      x_hi[n_index(points_ - 1) + c] = 0.0;
    }
  }
  x_lo[tau_index()] = model_.t_final_min / t_scale_;
  x_hi[tau_index()] = model_.t_final_max / t_scale_;

  const int m = num_constraints();
  g_lo.assign(m, 0.0);
  g_hi.assign(m, 0.0);
  const int path0 = 3 * static_cast<int>(defects_.size());
  for (int i = path0; i < m; ++i) {
    g_lo[i] = -1e19;  // IPOPT's default "minus infinity"
    g_hi[i] = w_bound * w_bound;
  }
}

double HermiteSimpsonNlp::objective(const double* x) const {
  double sum = 0.0;
  for (int j = 0; j < points_; ++j) {
    double l1 = 0.0;
    for (int c = 0; c < 16; ++c) l1 += x[p_index(j) + c];
    sum += weight(j) * l1;
  }
  return x[tau_index()] * sum;
}

void HermiteSimpsonNlp::objective_gradient(const double* x, double* grad) const {
  std::fill(grad, grad + num_variables(), 0.0);
  const double tau = x[tau_index()];
  double sum = 0.0;
  for (int j = 0; j < points_; ++j) {
    double l1 = 0.0;
    for (int c = 0; c < 16; ++c) {
      l1 += x[p_index(j) + c];
      grad[p_index(j) + c] = tau * weight(j);
    }
    sum += weight(j) * l1;
  }
  grad[tau_index()] = sum;
}

void HermiteSimpsonNlp::constraints(const double* x, double* g) const {
  std::vector<Vec3> f(points_);
  for (int j = 0; j < points_; ++j) f[j] = rhs(x, j);
  for (std::size_t d = 0; d < defects_.size(); ++d) {
    const double h = c_[d / 2] * x[tau_index()];  // defects 2k, 2k+1 belong to interval k
    Vec3 v = Vec3::Zero();
    for (const DefectTerm& term : defects_[d]) {
      v += term.alpha * Eigen::Map<const Vec3>(x + w_index(term.point)) + h * term.beta * f[term.point];
    }
    for (int r = 0; r < 3; ++r) g[3 * d + r] = v[r];
  }
  const int path0 = 3 * static_cast<int>(defects_.size());
  for (int j = 1; j + 1 < points_; ++j) {
    g[path0 + j - 1] = Eigen::Map<const Vec3>(x + w_index(j)).squaredNorm();
  }
}

void HermiteSimpsonNlp::jacobian_values(const double* x, double* values) const {
  const double tau = x[tau_index()];
  std::vector<Vec3> f(points_);
  for (int j = 0; j < points_; ++j) f[j] = rhs(x, j);
  std::size_t k = 0;
  for (std::size_t d = 0; d < defects_.size(); ++d) {
    const auto& defect = defects_[d];
    const double ck = c_[d / 2];
    const double h = ck * tau;
    Vec3 dtau = Vec3::Zero();
    for (const DefectTerm& term : defect) {
      const Eigen::Map<const Vec3> w(x + w_index(term.point));
      const Mat3 dw = term.alpha * Mat3::Identity() + h * term.beta * g_scaled_jacobian(w);
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) values[k++] = dw(r, c);
      }
      dtau += ck * term.beta * f[term.point];
      if (term.beta == 0.0) continue;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 8; ++c) values[k++] = h * term.beta * a_(r, c);
        for (int c = 0; c < 8; ++c) values[k++] = -h * term.beta * a_(r, c);
      }
    }
    for (int r = 0; r < 3; ++r) values[k++] = dtau[r];
  }
  for (int j = 1; j + 1 < points_; ++j) {
    for (int c = 0; c < 3; ++c) values[k++] = 2.0 * x[w_index(j) + c];
  }
}

void HermiteSimpsonNlp::hessian_values(const double* x, double sigma, const double* lambda,
                                       double* values) const {
  const double tau = x[tau_index()];
  std::vector<Mat3> hw(points_, Mat3::Zero());
  std::vector<Vec3> tw(points_, Vec3::Zero());
  std::vector<Vec8> tp(points_, Vec8::Zero());
  for (std::size_t d = 0; d < defects_.size(); ++d) {
    const Vec3 lam(lambda[3 * d], lambda[3 * d + 1], lambda[3 * d + 2]);
    const Mat3 hg = g_scaled_hessian(lam);
    const Vec8 at_lam = a_.transpose() * lam;
    const double ck = c_[d / 2];
    const double h = ck * tau;
    for (const DefectTerm& term : defects_[d]) {
      if (term.beta == 0.0) continue;
      const int j = term.point;
      const Eigen::Map<const Vec3> w(x + w_index(j));
      hw[j] += h * term.beta * hg;
      tw[j] += ck * term.beta * g_scaled_jacobian(w).transpose() * lam;
      tp[j] += ck * term.beta * at_lam;
    }
  }
  const int path0 = 3 * static_cast<int>(defects_.size());
  for (int j = 1; j + 1 < points_; ++j) hw[j] += 2.0 * lambda[path0 + j - 1] * Mat3::Identity();

  std::size_t k = 0;
  for (int j = 0; j < points_; ++j) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c <= r; ++c) values[k++] = hw[j](r, c);
    }
    for (int c = 0; c < 3; ++c) values[k++] = tw[j][c];
    const double obj = sigma * weight(j);
    for (int c = 0; c < 8; ++c) values[k++] = tp[j][c] + obj;   // (tau, p_j)
    for (int c = 0; c < 8; ++c) values[k++] = -tp[j][c] + obj;  // (tau, n_j)
  }
}

Vec3 HermiteSimpsonNlp::omega(const double* x, int j) const {
  return omega_scale_ * Eigen::Map<const Vec3>(x + w_index(j));
}

Vec8 HermiteSimpsonNlp::control(const double* x, int j) const {
  return model_.u_max * (Eigen::Map<const Vec8>(x + p_index(j)) - Eigen::Map<const Vec8>(x + n_index(j)));
}

void HermiteSimpsonNlp::set_point(double* x, int j, const Vec3& omega, const Vec8& u) const {
  Eigen::Map<Vec3>(x + w_index(j)) = omega / omega_scale_;
  for (int c = 0; c < 8; ++c) {
    const double v = u[c] / model_.u_max;
    x[p_index(j) + c] = std::max(v, 0.0);
    x[n_index(j) + c] = std::max(-v, 0.0);
  }
}

}  // namespace rocksteady::ground::planner
