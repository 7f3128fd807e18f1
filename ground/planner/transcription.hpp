// Hermite-Simpson direct transcription of the fuel-optimal despin problem, SPEC Eq. (44).
//
// The NLP is written here without any reference to the solver, so its derivatives can be checked
// against finite differences (tests/planner) and the IPOPT adapter (planner.cpp) stays a thin shell.
//
// Grid: N nodes over [0, t_f] at normalised positions s_0 = 0 < s_1 < ... < s_{N-1} = 1 (node k at
// t = s_k t_f; uniform unless given), t_f = t_scale * tau free in [tau_min, tau_max].
// Collocation points j = 0..P-1, P = 2N-1: even j are nodes, odd j the interval midpoints.
// At every point: scaled rate w_j = omega_j / omega_scale, and the split control
// u_j = u_max (p_j - n_j), p_j, n_j in [0, 1]^8 (the L1 cost becomes linear: |u| = u_max (p + n)
// at the optimum, where min(p, n) = 0 on every channel).
//
// Scaled dynamics, Eq. (41):  dw/dt = F(w, p, n) = g(w) + A (p - n),
//   g(w) = omega_scale J^-1 ((J w) x w),   A = u_max J^-1 B / omega_scale.
// Separated Hermite-Simpson defects on interval k (points a = 2k, m = 2k+1, b = 2k+2, h = c tau,
// c_k = t_scale (s_{k+1} - s_k)):
//   D1_k = w_m - (w_a + w_b)/2 - h/8 (F_a - F_b)           = 0
//   D2_k = w_b - w_a - h/6 (F_a + 4 F_m + F_b)             = 0
// Path constraint, Eq. (43): |w_j|^2 <= (eps_trans / omega_scale)^2 at the interior points.
// Boundary conditions, Eq. (43): w_0 = omega_init / omega_scale and w_{P-1} = 0 as fixed bounds.
// Cost (Simpson): J = tau sum_k (s_{k+1} - s_k) (L_a + 4 L_m + L_b)/6, L_j = sum_i (p_ji + n_ji),
// i.e. J = tau sum_j W_j L_j; the physical cost int |u|_1 dt = u_max t_scale J.
#pragma once

#include <vector>

#include "gnc/types.hpp"

namespace rocksteady::ground::planner {

using gnc::Mat3;
using gnc::Mat38;
using gnc::Vec3;
using gnc::Vec8;

struct TranscriptionModel {
  Mat3 j_hat{Mat3::Identity()};
  Mat38 b_hat{Mat38::Zero()};
  double u_max{200.0};
  double eps_trans{0.05236};
  Vec3 omega_init{Vec3::Zero()};
  int nodes{101};            // N >= 2
  // Normalised node positions s_k (size N, s_0 = 0, s_{N-1} = 1, strictly increasing); empty means
  // uniform. A non-uniform grid lets the intervals follow the tumble (ground/planner/README.md).
  std::vector<double> grid;
  double t_final_min{1.0};   // s
  double t_final_max{2.0};   // s (equal to t_final_min: fixed final time)
  // u_d(t_final) = 0 as well as omega_d(t_final) = 0: the plan can be continued by rest (the
  // long-horizon plans of planner.hpp), omega_d_dot(t_final) = 0 so the on-board cubic stays at 0.
  bool rest_at_end{false};
};

// Sparse triplet pattern (0-based row/column).
struct SparsityPattern {
  std::vector<int> rows;
  std::vector<int> cols;
};

class HermiteSimpsonNlp {
 public:
  static constexpr int kPointVars = 19;  // 3 rates + 8 positive + 8 negative parts

  explicit HermiteSimpsonNlp(const TranscriptionModel& model);

  int num_nodes() const { return nodes_; }
  int num_points() const { return points_; }
  int num_variables() const { return kPointVars * points_ + 1; }
  int num_constraints() const { return 6 * (nodes_ - 1) + interior_points(); }
  int tau_index() const { return kPointVars * points_; }
  int w_index(int j) const { return kPointVars * j; }
  int p_index(int j) const { return kPointVars * j + 3; }
  int n_index(int j) const { return kPointVars * j + 11; }

  double omega_scale() const { return omega_scale_; }
  double t_scale() const { return t_scale_; }
  // Normalised time of collocation point j (nodes at s_k, midpoints halfway).
  double point_fraction(int j) const;
  double cost_scale() const { return model_.u_max * t_scale_; }  // N s per unit of objective
  const TranscriptionModel& model() const { return model_; }

  void bounds(std::vector<double>& x_lo, std::vector<double>& x_hi, std::vector<double>& g_lo,
              std::vector<double>& g_hi) const;

  double objective(const double* x) const;
  void objective_gradient(const double* x, double* grad) const;
  void constraints(const double* x, double* g) const;

  const SparsityPattern& jacobian_pattern() const { return jac_; }
  void jacobian_values(const double* x, double* values) const;
  // Hessian of sigma * f + sum lambda_i g_i, lower triangle (row >= col).
  const SparsityPattern& hessian_pattern() const { return hess_; }
  void hessian_values(const double* x, double sigma, const double* lambda, double* values) const;

  // Physical quantities at a point (for packing guesses and reading solutions).
  Vec3 omega(const double* x, int j) const;
  Vec8 control(const double* x, int j) const;  // N
  double t_final(const double* x) const { return t_scale_ * x[tau_index()]; }
  void set_point(double* x, int j, const Vec3& omega, const Vec8& u) const;
  void set_t_final(double* x, double t_final) const { x[tau_index()] = t_final / t_scale_; }

  // Scaled right-hand side pieces (exposed for tests).
  Vec3 g_scaled(const Vec3& w) const;
  Mat3 g_scaled_jacobian(const Vec3& w) const;
  Mat3 g_scaled_hessian(const Vec3& lambda) const;  // Hessian of lambda' g(w); constant in w

 private:
  struct DefectTerm {
    int point;
    double alpha;  // coefficient of w_point
    double beta;   // coefficient of h F_point
  };
  int interior_points() const { return points_ - 2; }
  Vec3 rhs(const double* x, int j) const;  // F at point j (scaled)
  double weight(int j) const { return weights_[j]; }  // Simpson weight W_j (see header)

  TranscriptionModel model_;
  int nodes_;
  int points_;
  double omega_scale_;
  double t_scale_;
  std::vector<double> s_;        // node positions s_k
  std::vector<double> c_;        // per interval: t_scale (s_{k+1} - s_k)
  std::vector<double> weights_;  // per point: W_j
  Mat3 j_inv_;
  Eigen::Matrix<double, 3, 8> a_;  // u_max J^-1 B / omega_scale
  // Defect d (rows 3d..3d+2) is sum_terms alpha w + c tau beta F.
  std::vector<std::vector<DefectTerm>> defects_;
  SparsityPattern jac_;
  SparsityPattern hess_;
};

}  // namespace rocksteady::ground::planner
