#include "ground/planner/planner.hpp"

#include <Eigen/Dense>
#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <type_traits>

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include "ground/planner/transcription.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"

namespace rocksteady::ground::planner {

namespace {

Vec3 dynamics(const PlanModel& model, const Mat3& j_inv, const Vec3& omega, const Vec8& u) {
  const Vec3 j_omega = model.j_hat * omega;
  return j_inv * (j_omega.cross(omega) + model.b_hat * u);  // Eq. (41)
}

// IPOPT adapter around the solver-independent transcription.
class DespinTnlp : public Ipopt::TNLP {
 public:
  DespinTnlp(const HermiteSimpsonNlp& nlp, std::vector<double> x0)
      : nlp_(nlp), x0_(std::move(x0)) {
    nlp_.bounds(x_lo_, x_hi_, g_lo_, g_hi_);
  }

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g,
                    Ipopt::Index& nnz_h_lag, IndexStyleEnum& index_style) override {
    n = nlp_.num_variables();
    m = nlp_.num_constraints();
    nnz_jac_g = static_cast<Ipopt::Index>(nlp_.jacobian_pattern().rows.size());
    nnz_h_lag = static_cast<Ipopt::Index>(nlp_.hessian_pattern().rows.size());
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index m,
                       Ipopt::Number* g_l, Ipopt::Number* g_u) override {
    std::copy(x_lo_.begin(), x_lo_.begin() + n, x_l);
    std::copy(x_hi_.begin(), x_hi_.begin() + n, x_u);
    std::copy(g_lo_.begin(), g_lo_.begin() + m, g_l);
    std::copy(g_hi_.begin(), g_hi_.begin() + m, g_u);
    return true;
  }

  bool get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z,
                          Ipopt::Number* /*z_l*/, Ipopt::Number* /*z_u*/, Ipopt::Index /*m*/,
                          bool init_lambda, Ipopt::Number* /*lambda*/) override {
    if (!init_x || init_z || init_lambda) return false;
    std::copy(x0_.begin(), x0_.begin() + n, x);
    return true;
  }

  bool eval_f(Ipopt::Index /*n*/, const Ipopt::Number* x, bool /*new_x*/,
              Ipopt::Number& obj) override {
    obj = nlp_.objective(x);
    return std::isfinite(obj);
  }
  bool eval_grad_f(Ipopt::Index /*n*/, const Ipopt::Number* x, bool /*new_x*/,
                   Ipopt::Number* grad) override {
    nlp_.objective_gradient(x, grad);
    return true;
  }
  bool eval_g(Ipopt::Index /*n*/, const Ipopt::Number* x, bool /*new_x*/, Ipopt::Index /*m*/,
              Ipopt::Number* g) override {
    nlp_.constraints(x, g);
    return true;
  }
  bool eval_jac_g(Ipopt::Index /*n*/, const Ipopt::Number* x, bool /*new_x*/, Ipopt::Index /*m*/,
                  Ipopt::Index nele, Ipopt::Index* irow, Ipopt::Index* jcol,
                  Ipopt::Number* values) override {
    if (values == nullptr) {
      const SparsityPattern& p = nlp_.jacobian_pattern();
      std::copy(p.rows.begin(), p.rows.begin() + nele, irow);
      std::copy(p.cols.begin(), p.cols.begin() + nele, jcol);
    } else {
      nlp_.jacobian_values(x, values);
    }
    return true;
  }
  bool eval_h(Ipopt::Index /*n*/, const Ipopt::Number* x, bool /*new_x*/, Ipopt::Number obj_factor,
              Ipopt::Index /*m*/, const Ipopt::Number* lambda, bool /*new_lambda*/,
              Ipopt::Index nele, Ipopt::Index* irow, Ipopt::Index* jcol,
              Ipopt::Number* values) override {
    if (values == nullptr) {
      const SparsityPattern& p = nlp_.hessian_pattern();
      std::copy(p.rows.begin(), p.rows.begin() + nele, irow);
      std::copy(p.cols.begin(), p.cols.begin() + nele, jcol);
    } else {
      nlp_.hessian_values(x, obj_factor, lambda, values);
    }
    return true;
  }

  void finalize_solution(Ipopt::SolverReturn status, Ipopt::Index n, const Ipopt::Number* x,
                         const Ipopt::Number* /*z_l*/, const Ipopt::Number* /*z_u*/,
                         Ipopt::Index /*m*/, const Ipopt::Number* /*g*/,
                         const Ipopt::Number* /*lambda*/, Ipopt::Number obj_value,
                         const Ipopt::IpoptData* /*ip_data*/,
                         Ipopt::IpoptCalculatedQuantities* /*ip_cq*/) override {
    status_ = status;
    x_.assign(x, x + n);
    objective_ = obj_value;
  }

  Ipopt::SolverReturn status() const { return status_; }
  const std::vector<double>& solution() const { return x_; }
  double objective() const { return objective_; }

 private:
  const HermiteSimpsonNlp& nlp_;
  std::vector<double> x0_;
  std::vector<double> x_lo_, x_hi_, g_lo_, g_hi_;
  std::vector<double> x_;
  double objective_{0.0};
  Ipopt::SolverReturn status_{Ipopt::INTERNAL_ERROR};
};

const char* status_text(Ipopt::SolverReturn s) {
  switch (s) {
    case Ipopt::SUCCESS: return "optimal solution found";
    case Ipopt::MAXITER_EXCEEDED: return "maximum number of iterations exceeded";
    case Ipopt::CPUTIME_EXCEEDED: return "CPU time limit exceeded";
    case Ipopt::STOP_AT_TINY_STEP: return "stopped at a tiny step";
    case Ipopt::STOP_AT_ACCEPTABLE_POINT: return "stopped at an acceptable (not optimal) point";
    case Ipopt::LOCAL_INFEASIBILITY: return "converged to a point of local infeasibility";
    case Ipopt::USER_REQUESTED_STOP: return "stopped by the user";
    case Ipopt::FEASIBLE_POINT_FOUND: return "feasible point found";
    case Ipopt::DIVERGING_ITERATES: return "iterates diverging";
    case Ipopt::RESTORATION_FAILURE: return "restoration phase failed";
    case Ipopt::ERROR_IN_STEP_COMPUTATION: return "error in step computation";
    case Ipopt::INVALID_NUMBER_DETECTED: return "invalid number detected";
    case Ipopt::TOO_FEW_DEGREES_OF_FREEDOM: return "too few degrees of freedom";
    case Ipopt::INVALID_OPTION: return "invalid option";
    case Ipopt::OUT_OF_MEMORY: return "out of memory";
    case Ipopt::INTERNAL_ERROR: return "internal error";
    default: return "unknown IPOPT status";
  }
}

// Set in a candidate worker process (solve_candidates).
bool g_candidate_worker = false;

struct SolveOutcome {
  bool ok{false};
  std::string error;
  int iterations{0};
  double seconds{0.0};
  double cost_ns{0.0};
  double t_final{0.0};
  std::vector<PlanSample> samples;
};

// Initial guess [Rocksteady choice]: a dynamically consistent despin that removes the momentum at a
// constant rate. The torque is -(|H0|/t_f) e, with e the unit momentum direction in the body, so
// H = |H0| (1 - t/t_f) e reaches zero exactly at t_f while e turns with the body (de/dt = e x omega,
// from Eq. 41). u is the minimum-norm control of that torque, clipped to u_max.
std::vector<double> momentum_ramp_guess(const HermiteSimpsonNlp& nlp, const PlanModel& model) {
  std::vector<double> x(nlp.num_variables(), 0.0);
  const double t_f = nlp.t_scale();
  nlp.set_t_final(x.data(), t_f);
  const Eigen::Matrix<double, 8, 3> b_pinv =
      model.b_hat.transpose() * (model.b_hat * model.b_hat.transpose()).inverse();
  const Mat3 j_inv = model.j_hat.inverse();
  const Vec3 h0 = model.j_hat * model.omega_init;
  const double h0_norm = h0.norm();
  const auto e_dot = [&](double t, const Vec3& e) -> Vec3 {
    const Vec3 omega = h0_norm * (1.0 - t / t_f) * (j_inv * e);
    return e.cross(omega);
  };
  const int p = nlp.num_points();
  constexpr int kSubsteps = 16;
  Vec3 e = h0 / h0_norm;
  for (int j = 0; j < p; ++j) {
    const double t = t_f * nlp.point_fraction(j);
    const double dt_point = j + 1 < p ? t_f * nlp.point_fraction(j + 1) - t : 0.0;
    const Vec3 omega = h0_norm * (1.0 - t / t_f) * (j_inv * e);
    const Vec8 u = (b_pinv * (-h0_norm / t_f * e)).cwiseMax(-model.u_max).cwiseMin(model.u_max);
    nlp.set_point(x.data(), j, j == 0 ? model.omega_init : omega, u);
    const double dt = dt_point / kSubsteps;
    for (int k = 0; k < kSubsteps; ++k) {  // RK4 on e, renormalised
      const double tk = t + k * dt;
      const Vec3 k1 = e_dot(tk, e);
      const Vec3 k2 = e_dot(tk + 0.5 * dt, e + 0.5 * dt * k1);
      const Vec3 k3 = e_dot(tk + 0.5 * dt, e + 0.5 * dt * k2);
      const Vec3 k4 = e_dot(tk + dt, e + dt * k3);
      e = (e + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)).normalized();
    }
  }
  return x;
}

// Guess on a finer grid from a coarser plan's samples (linear interpolation in normalised time).
std::vector<double> guess_from_samples(const HermiteSimpsonNlp& nlp,
                                       const std::vector<PlanSample>& samples) {
  std::vector<double> x(nlp.num_variables(), 0.0);
  // The warm plan's final time when it lies in this problem's range; else this problem's (a shorter
  // plan is extended by rest, a longer one cut).
  double t_f = samples.back().t;
  if (t_f < nlp.model().t_final_min || t_f > nlp.model().t_final_max) t_f = nlp.t_scale();
  nlp.set_t_final(x.data(), t_f);
  const int p = nlp.num_points();
  std::size_t k = 0;
  for (int j = 0; j < p; ++j) {
    const double t = t_f * nlp.point_fraction(j);
    while (k + 2 < samples.size() && samples[k + 1].t < t) ++k;
    const PlanSample& a = samples[k];
    const PlanSample& b = samples[k + 1];
    if (t > samples.back().t) {  // after the warm plan: at rest
      nlp.set_point(x.data(), j, Vec3::Zero(), Vec8::Zero());
      continue;
    }
    const double s = std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0);
    nlp.set_point(x.data(), j, (1 - s) * a.omega_d + s * b.omega_d, (1 - s) * a.u_d + s * b.u_d);
  }
  return x;
}

struct SolveSpec {
  int nodes{0};
  std::vector<double> grid;  // empty: uniform
  double t_min{0.0};
  double t_max{0.0};
  const std::vector<PlanSample>* warm{nullptr};
  double warm_mu{0.0};  // > 0: warm-start the barrier at this mu (needs warm)
  bool rest_at_end{false};  // u_d(t_final) = 0 too (a rest tail follows)
};

SolveOutcome solve_once(const PlanModel& model, const PlanSettings& settings,
                        const SolveSpec& spec) {
  const int nodes = spec.nodes;
  const double t_min = spec.t_min;
  const double t_max = spec.t_max;
  const std::vector<PlanSample>* warm = spec.warm;
  SolveOutcome out;
  TranscriptionModel tm;
  tm.j_hat = model.j_hat;
  tm.b_hat = model.b_hat;
  tm.u_max = model.u_max;
  tm.eps_trans = model.eps_trans;
  tm.omega_init = model.omega_init;
  tm.nodes = nodes;
  tm.grid = spec.grid;
  tm.t_final_min = t_min;
  tm.t_final_max = t_max;
  tm.rest_at_end = spec.rest_at_end;
  const HermiteSimpsonNlp nlp(tm);
  std::vector<double> x0 =
      warm != nullptr ? guess_from_samples(nlp, *warm) : momentum_ramp_guess(nlp, model);

  Ipopt::SmartPtr<DespinTnlp> tnlp = new DespinTnlp(nlp, std::move(x0));
  // One IPOPT solve at a time in a process: Debian's IPOPT factorises with sequential MUMPS, whose
  // MPI stub and Fortran state are process-global (two campaign workers re-planning at once ended
  // in "double free or corruption"). The solves do not depend on each other, so results are
  // unchanged; only concurrent callers wait.
  // A candidate worker (solve_candidates) is a single-threaded child with its own copy of MUMPS, and
  // its copy of the mutex may have been taken by another thread of the parent at the fork.
  static std::mutex ipopt_mutex;
  std::unique_lock<std::mutex> ipopt_lock(ipopt_mutex, std::defer_lock);
  if (!g_candidate_worker) ipopt_lock.lock();
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetIntegerValue("print_level", settings.print_level);
  if (settings.print_level >= 5) app->Options()->SetStringValue("print_timing_statistics", "yes");
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetNumericValue("tol", settings.tolerance);
  app->Options()->SetNumericValue("constr_viol_tol", 1e-10);
  app->Options()->SetIntegerValue("max_iter", settings.max_iterations);
  app->Options()->SetNumericValue("bound_relax_factor", 0.0);  // bounds hold exactly
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  // No "acceptable" stop: a solve converges to `tolerance` or fails (case 3 at 2780 s stopped at
  // an acceptable point after 75 iterations and converged at 79 without the stop).
  app->Options()->SetIntegerValue("acceptable_iter", 0);
  if (warm != nullptr && spec.warm_mu > 0.0) {
    // Warm start [Rocksteady choice]: the guess is a converged plan of a nearby problem (another
    // grid, a shorter horizon, an earlier state), so the barrier starts small and the bounds are
    // barely pushed; measured on case 1 at 5600 s the refinement re-solve takes 59 instead of 292
    // iterations.
    app->Options()->SetStringValue("mu_strategy", "monotone");
    app->Options()->SetNumericValue("mu_init", spec.warm_mu);
    // A warm start that has not converged by then is not near its answer: solve() starts over cold.
    app->Options()->SetIntegerValue("max_iter", std::min(settings.max_iterations, kWarmMaxIterations));
    app->Options()->SetNumericValue("bound_push", 1e-6);
    app->Options()->SetNumericValue("bound_frac", 1e-6);
    app->Options()->SetStringValue("bound_mult_init_method", "mu-based");
  }
  app->Options()->SetStringValue("hessian_approximation", "exact");
  if (app->Initialize() != Ipopt::Solve_Succeeded) {
    out.error = "IPOPT failed to initialise";
    return out;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(tnlp);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  Ipopt::SmartPtr<Ipopt::SolveStatistics> stats = app->Statistics();
  if (Ipopt::IsValid(stats)) out.iterations = stats->IterationCount();
  if (status != Ipopt::Solve_Succeeded || tnlp->status() != Ipopt::SUCCESS) {
    std::ostringstream msg;
    msg << "IPOPT did not converge (" << status_text(tnlp->status()) << ", " << out.iterations
        << " iterations, " << nodes << " nodes)";
    out.error = msg.str();
    return out;
  }
  const std::vector<double>& x = tnlp->solution();
  out.t_final = nlp.t_final(x.data());
  out.cost_ns = nlp.cost_scale() * nlp.objective(x.data());
  const Mat3 j_inv = model.j_hat.inverse();
  const int p = nlp.num_points();
  out.samples.resize(p);
  for (int j = 0; j < p; ++j) {
    PlanSample& s = out.samples[j];
    s.t = out.t_final * nlp.point_fraction(j);
    s.omega_d = nlp.omega(x.data(), j);
    s.u_d = nlp.control(x.data(), j);
  }
  out.samples.front().omega_d = model.omega_init;  // exact boundary values, Eq. (43)
  out.samples.back().omega_d = Vec3::Zero();
  out.samples.back().t = out.t_final;
  for (PlanSample& s : out.samples) s.omega_d_dot = dynamics(model, j_inv, s.omega_d, s.u_d);
  out.ok = true;
  return out;
}

// A warm-started solve that does not converge is repeated from the same guess with the default
// (adaptive) barrier strategy; iterations and time add up.
SolveOutcome solve(const PlanModel& model, const PlanSettings& settings, const SolveSpec& spec) {
  SolveOutcome out = solve_once(model, settings, spec);
  if (out.ok || spec.warm_mu <= 0.0) return out;
  SolveSpec cold = spec;
  cold.warm_mu = 0.0;
  SolveOutcome again = solve_once(model, settings, cold);
  again.iterations += out.iterations;
  again.seconds += out.seconds;
  return again;
}

void check_model(const PlanModel& m, int nodes) {
  if (!m.j_hat.allFinite() || !m.b_hat.allFinite() || !m.omega_init.allFinite() ||
      !std::isfinite(m.u_max) || !std::isfinite(m.eps_trans)) {
    throw std::invalid_argument("model has non-finite entries");
  }
  if ((m.j_hat - m.j_hat.transpose()).norm() > 1e-9 * m.j_hat.norm()) {
    throw std::invalid_argument("J_hat is not symmetric");
  }
  if (Eigen::SelfAdjointEigenSolver<Mat3>(m.j_hat).eigenvalues().minCoeff() <= 0.0) {
    throw std::invalid_argument("J_hat is not positive definite");
  }
  const Mat3 bbt = m.b_hat * m.b_hat.transpose();
  if (Eigen::SelfAdjointEigenSolver<Mat3>(bbt).eigenvalues().minCoeff() <= 1e-12 * bbt.norm()) {
    throw std::invalid_argument("B_hat does not have full rank: some torque direction is missing");
  }
  if (!(m.u_max > 0.0) || !(m.eps_trans > 0.0)) {
    throw std::invalid_argument("u_max and eps_trans must be positive");
  }
  if (m.omega_init.norm() > m.eps_trans) {
    throw std::invalid_argument("|omega_init| exceeds eps_trans: Eq. (43) is infeasible at t = 0");
  }
  if (m.omega_init.norm() == 0.0) throw std::invalid_argument("omega_init is already at rest");
  if (nodes < 3 || 2 * nodes - 1 > gnc::kMaxTrajectorySamples) {
    std::ostringstream msg;
    msg << "nodes must be in [3, " << (gnc::kMaxTrajectorySamples + 1) / 2
        << "] (2N-1 samples fit the on-board table)";
    throw std::invalid_argument(msg.str());
  }
}


int max_nodes() { return (gnc::kMaxTrajectorySamples + 1) / 2; }

// Automatic uniform grid: one node every kUniformStep seconds, at least kDefaultNodes, at most what
// the on-board table holds.
int automatic_uniform_nodes(double t_f) {
  const double n = std::ceil(t_f / kUniformStep) + 1.0;
  return static_cast<int>(std::clamp(n, static_cast<double>(kDefaultNodes),
                                     static_cast<double>(max_nodes())));
}

std::vector<double> uniform_grid(int nodes) {
  const int n = std::max(nodes, 2);
  std::vector<double> g(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) g[k] = static_cast<double>(k) / (n - 1);
  g[static_cast<std::size_t>(n - 1)] = 1.0;
  return g;
}

// Every other node of a grid, the last one kept: (N+1)/2 nodes (N odd), N/2 + 1 (N even, the last
// interval then spans one of the grid's).
std::vector<double> coarsened(const std::vector<double>& grid) {
  std::vector<double> g;
  g.reserve(grid.size() / 2 + 2);
  for (std::size_t k = 0; k < grid.size(); k += 2) g.push_back(grid[k]);
  if (g.back() != grid.back()) g.push_back(grid.back());
  return g;
}

std::vector<double> bisected(const std::vector<double>& grid) {
  std::vector<double> g;
  g.reserve(2 * grid.size() - 1);
  for (std::size_t k = 0; k + 1 < grid.size(); ++k) {
    g.push_back(grid[k]);
    g.push_back(0.5 * (grid[k] + grid[k + 1]));
  }
  g.push_back(1.0);
  return g;
}

// Tumble-following grid [Rocksteady choice]: node spacing inversely proportional to the body rate,
// so every interval covers about the same rotation angle (2 pi / intervals_per_turn), whatever the
// horizon. The rate is floored at kTumbleFloor |omega(0)| so that slow stretches keep some nodes.
// nodes > 0 fixes the node count; else it follows from the total angle.
template <typename Rate>
std::vector<double> tumble_grid(const Rate& rate, double t_f, double intervals_per_turn, int nodes,
                                int max) {
  constexpr int kFine = 20000;  // quadrature of the angle
  const double floor = kTumbleFloor * rate(0.0);
  std::vector<double> angle(kFine + 1, 0.0);
  for (int i = 0; i < kFine; ++i) {
    const double ta = t_f * i / kFine;
    const double tb = t_f * (i + 1) / kFine;
    angle[i + 1] = angle[i] + 0.5 * (tb - ta) *
                                  (std::max(rate(ta), floor) + std::max(rate(tb), floor));
  }
  const double total = angle.back();
  if (nodes <= 0) {
    const double turns = total / (2.0 * 3.14159265358979323846);
    nodes = static_cast<int>(std::ceil(turns * intervals_per_turn)) + 1;
  }
  nodes = std::clamp(nodes, kMinTumbleNodes, max);
  std::vector<double> g(nodes, 0.0);
  int i = 0;
  for (int k = 1; k + 1 < nodes; ++k) {
    const double target = total * k / (nodes - 1);
    while (i < kFine && angle[i + 1] < target) ++i;
    const double f = (target - angle[i]) / (angle[i + 1] - angle[i]);
    g[k] = (i + f) / kFine;
  }
  g.back() = 1.0;
  return g;
}


// Local open-loop error of each interval: RK4 (32 steps) from the interval's first node under the
// quadratic control interpolant, compared with the plan's next node (the per-interval part of the
// verification's propagation check).
std::vector<double> interval_errors(const PlanModel& model, const std::vector<PlanSample>& samples) {
  const Mat3 j_inv = model.j_hat.inverse();
  std::vector<double> e;
  constexpr int kSteps = 32;
  for (std::size_t a = 0; a + 2 < samples.size(); a += 2) {
    const double ta = samples[a].t;
    const double h = samples[a + 2].t - ta;
    const Vec8& ua = samples[a].u_d;
    const Vec8& um = samples[a + 1].u_d;
    const Vec8& ub = samples[a + 2].u_d;
    const auto u_at = [&](double t) -> Vec8 {
      const double s = (t - ta) / h;
      return (2 * s - 1) * (s - 1) * ua + 4 * s * (1 - s) * um + s * (2 * s - 1) * ub;
    };
    Vec3 omega = samples[a].omega_d;
    const double dt = h / kSteps;
    for (int k = 0; k < kSteps; ++k) {
      const double t = ta + k * dt;
      const Vec3 k1 = dynamics(model, j_inv, omega, u_at(t));
      const Vec3 k2 = dynamics(model, j_inv, omega + 0.5 * dt * k1, u_at(t + 0.5 * dt));
      const Vec3 k3 = dynamics(model, j_inv, omega + 0.5 * dt * k2, u_at(t + 0.5 * dt));
      const Vec3 k4 = dynamics(model, j_inv, omega + dt * k3, u_at(t + dt));
      omega += dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    e.push_back((omega - samples[a + 2].omega_d).norm());
  }
  return e;
}

// Error-equidistributing grid [Rocksteady choice] (mesh refinement after a first solve). Hermite-
// Simpson's local error on an interval of length h is C h^5; with C_k = e_k / h_k^5 from the first
// plan, intervals of length h(t) = (e / C(t))^(1/5) all make the same error e. Choosing e =
// limit / N (so that N such errors add up to `limit`, the caller's fraction of the verification's
// limit) gives N = (I^5 / limit)^(1/4), I = int C^(1/5) dt. The density is floored by `turns_floor`
// intervals per turn of the body (the plan's own rate), so that no stretch goes unresolved.
std::vector<double> error_grid(const std::vector<PlanSample>& samples, const std::vector<double>& err,
                               double limit, double turns_floor, int max) {
  const double t_f = samples.back().t;
  const std::size_t k_count = err.size();
  std::vector<double> density(k_count);  // intervals per second on each old interval
  double integral = 0.0;
  for (std::size_t k = 0; k < k_count; ++k) {
    const double h = samples[2 * k + 2].t - samples[2 * k].t;
    density[k] = std::pow(std::max(err[k], 1e-300), 0.2) / h;  // C^(1/5)
    integral += density[k] * h;
  }
  const double n_err = std::pow(std::pow(integral, 5.0) / limit, 0.25);
  const double scale = n_err / std::max(integral, 1e-300);  // density in intervals per second
  std::vector<double> cumulative(k_count + 1, 0.0);
  for (std::size_t k = 0; k < k_count; ++k) {
    const double h = samples[2 * k + 2].t - samples[2 * k].t;
    const double w = 0.5 * (samples[2 * k].omega_d.norm() + samples[2 * k + 2].omega_d.norm());
    const double floor = turns_floor * w / (2.0 * 3.14159265358979323846);
    cumulative[k + 1] = cumulative[k] + h * std::max(scale * density[k], floor);
  }
  const int nodes = std::clamp(static_cast<int>(std::ceil(cumulative.back())) + 1, kMinTumbleNodes, max);
  std::vector<double> g(nodes, 0.0);
  std::size_t k = 0;
  for (int i = 1; i + 1 < nodes; ++i) {
    const double target = cumulative.back() * i / (nodes - 1);
    while (k + 1 < k_count && cumulative[k + 1] < target) ++k;
    const double f = (target - cumulative[k]) / (cumulative[k + 1] - cumulative[k]);
    g[i] = (samples[2 * k].t + f * (samples[2 * k + 2].t - samples[2 * k].t)) / t_f;
  }
  g.back() = 1.0;
  for (int i = 1; i < nodes; ++i) g[i] = std::max(g[i], g[i - 1] + 1e-9);
  g.back() = 1.0;
  return g;
}

}  // namespace

void resolve_final_time_bounds(const PlanModel& model, const PlanSettings& settings, double& t_min,
                               double& t_max) {
  double torque_bound = 0.0;
  for (int i = 0; i < gnc::kChannels; ++i) torque_bound += model.b_hat.col(i).norm();
  torque_bound *= model.u_max;
  const double t_lower = (model.j_hat * model.omega_init).norm() / torque_bound;
  t_max = settings.t_final_max > 0.0 ? settings.t_final_max : kHorizonFactor * t_lower;
  if (!settings.free_final_time) {
    t_min = t_max;  // fixed final time (see planner.hpp)
  } else {
    t_min = settings.t_final_min > 0.0 ? settings.t_final_min : t_lower;
  }
}

Verification verify_samples(const PlanModel& model, const std::vector<PlanSample>& samples,
                            double propagation_limit) {
  Verification v;
  const auto fail = [&v](const std::string& why) {
    if (v.failure.empty()) v.failure = why;
  };
  if (samples.size() < 3 || samples.size() % 2 == 0) {
    v.failure = "sample count must be odd and >= 3 (nodes and midpoints)";
    return v;
  }
  const Mat3 j_inv = model.j_hat.inverse();
  const double w0 = model.omega_init.norm();
  const std::size_t p = samples.size();
  std::vector<Vec3> f(p);
  for (std::size_t j = 0; j < p; ++j) {
    const PlanSample& s = samples[j];
    f[j] = dynamics(model, j_inv, s.omega_d, s.u_d);
    v.max_rate_excess = std::max(v.max_rate_excess, s.omega_d.norm() - model.eps_trans);
    v.max_control_excess =
        std::max(v.max_control_excess, s.u_d.cwiseAbs().maxCoeff() - model.u_max);
  }
  // Hermite-Simpson defects from the samples themselves (independent of the NLP's scaling).
  for (std::size_t a = 0; a + 2 < p; a += 2) {
    const PlanSample& sa = samples[a];
    const PlanSample& sm = samples[a + 1];
    const PlanSample& sb = samples[a + 2];
    const double h = sb.t - sa.t;
    const Vec3 d1 = sm.omega_d - 0.5 * (sa.omega_d + sb.omega_d) - h / 8.0 * (f[a] - f[a + 2]);
    const Vec3 d2 = sb.omega_d - sa.omega_d - h / 6.0 * (f[a] + 4.0 * f[a + 1] + f[a + 2]);
    v.max_defect = std::max({v.max_defect, d1.norm(), d2.norm()});
  }
  v.boundary_error = (samples.front().omega_d - model.omega_init).norm() +
                     samples.back().omega_d.norm();

  // Open-loop propagation of u_d (quadratic through the node, midpoint, node values, the control
  // interpolant that Hermite-Simpson integrates exactly) with classical RK4, 32 steps per interval.
  Vec3 omega = model.omega_init;
  constexpr int kSteps = 32;
  for (std::size_t a = 0; a + 2 < p; a += 2) {
    const double ta = samples[a].t;
    const double h = samples[a + 2].t - ta;
    const Vec8& ua = samples[a].u_d;
    const Vec8& um = samples[a + 1].u_d;
    const Vec8& ub = samples[a + 2].u_d;
    const auto u_at = [&](double t) -> Vec8 {
      const double s = (t - ta) / h;  // Lagrange basis on s = 0, 1/2, 1
      return (2 * s - 1) * (s - 1) * ua + 4 * s * (1 - s) * um + s * (2 * s - 1) * ub;
    };
    const double dt = h / kSteps;
    for (int k = 0; k < kSteps; ++k) {
      const double t = ta + k * dt;
      const Vec3 k1 = dynamics(model, j_inv, omega, u_at(t));
      const Vec3 k2 = dynamics(model, j_inv, omega + 0.5 * dt * k1, u_at(t + 0.5 * dt));
      const Vec3 k3 = dynamics(model, j_inv, omega + 0.5 * dt * k2, u_at(t + 0.5 * dt));
      const Vec3 k4 = dynamics(model, j_inv, omega + dt * k3, u_at(t + dt));
      omega += dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
      if (k + 1 == kSteps / 2) {
        v.propagation_error =
            std::max(v.propagation_error, (omega - samples[a + 1].omega_d).norm());
      }
    }
    v.propagation_error = std::max(v.propagation_error, (omega - samples[a + 2].omega_d).norm());
  }
  v.propagated_final_rate = omega.norm();

  // Tolerances [Rocksteady choice]: the NLP is solved to 1e-9 (scaled), so defects, bounds and
  // boundary values are at round-off; the propagation limit covers the transcription error.
  const auto limit = [](const char* what, double value, double bound, const char* unit) {
    std::ostringstream msg;
    msg << what << " (" << value << " " << unit << " > " << bound << " " << unit << ")";
    return msg.str();
  };
  if (!(v.max_defect <= 1e-7 * w0)) {
    fail(limit("dynamics defects above tolerance", v.max_defect, 1e-7 * w0, "rad/s"));
  }
  if (!(v.max_rate_excess <= 1e-9 * model.eps_trans)) {
    fail(limit("|omega_d| exceeds eps_trans", v.max_rate_excess, 1e-9 * model.eps_trans, "rad/s"));
  }
  if (!(v.max_control_excess <= 1e-9 * model.u_max)) {
    fail(limit("|u_d| exceeds u_max", v.max_control_excess, 1e-9 * model.u_max, "N"));
  }
  if (!(v.boundary_error == 0.0)) fail(limit("boundary conditions not met", v.boundary_error, 0.0, "rad/s"));
  if (!(v.propagation_error <= propagation_limit * w0)) {
    fail(limit("open-loop propagation of u_d does not reproduce omega_d; refine the grid",
               v.propagation_error, propagation_limit * w0, "rad/s"));
  }
  if (!(v.propagated_final_rate <= propagation_limit * w0)) {
    fail(limit("open-loop propagation of u_d does not end near rest", v.propagated_final_rate,
               propagation_limit * w0, "rad/s"));
  }
  v.passed = v.failure.empty();
  return v;
}

namespace {

PlanResult plan_impl(const PlanProblem& problem, bool rest_at_end, SolveSpec* grid_out = nullptr);

// The grid-convergence check of a plan solved on `spec`'s grid (PlanSettings::refinement_check):
// re-solved on every other node (kCoarsen) or on every interval halved (kBisect), warm-started from
// the plan; the fuel must change by less than refinement_limit. Fills r.verification's refinement
// fields; false (with r.error) when the check fails.
bool check_refinement(const PlanModel& model, const PlanSettings& settings, const SolveSpec& spec,
                      PlanResult& r) {
  SolveSpec fine_spec = spec;
  const bool coarsen = settings.refinement_check == PlanSettings::RefinementCheck::kCoarsen &&
                       spec.grid.size() >= 5;
  // Coarsened: the coarse grid's points (its nodes and midpoints) are the plan's nodes on a uniform
  // grid, so the warm start is the plan's own values there and the solve only re-balances them.
  fine_spec.grid = coarsen ? coarsened(spec.grid) : bisected(spec.grid);
  fine_spec.nodes = static_cast<int>(fine_spec.grid.size());
  r.verification.refined_nodes = fine_spec.nodes;
  fine_spec.warm = &r.samples;
  fine_spec.warm_mu = kWarmMu;
  const SolveOutcome fine = solve(model, settings, fine_spec);
  r.verification.refined_iterations = fine.iterations;
  r.verification.refined_seconds = fine.seconds;
  if (!fine.ok) {
    r.error = std::string("verification failed: ") + (coarsen ? "coarsened" : "refined") +
              " grid: " + fine.error;
    return false;
  }
  r.verification.refinement_checked = true;
  r.verification.refined_fuel_kg = fine.cost_ns / (kIsp * kG0);
  r.verification.refinement_change =
      std::abs(r.verification.refined_fuel_kg - r.fuel_kg) / r.fuel_kg;
  if (!(r.verification.refinement_change < settings.refinement_limit)) {
    std::ostringstream msg;
    msg << (coarsen ? "grid coarsening (" : "grid refinement (") << r.nodes << " -> "
        << fine_spec.nodes
        << " nodes) changes the fuel by " << 100.0 * r.verification.refinement_change
        << " % (limit " << 100.0 * settings.refinement_limit << " %)";
    r.verification.passed = false;
    r.verification.failure = msg.str();
    r.error = "verification failed: " + msg.str();
    return false;
  }
  return true;
}

// One candidate despin of a long horizon: its plan (verified, not yet grid-checked) and its grid.
struct Candidate {
  PlanResult result;
  SolveSpec spec;
};

Candidate solve_candidate(const PlanProblem& problem, double horizon) {
  PlanProblem sub = problem;
  sub.settings.t_final_max = horizon;
  sub.settings.active_horizon_max = -1.0;  // this horizon in full
  sub.settings.verify_refinement = false;
  Candidate c;
  c.result = plan_impl(sub, true, &c.spec);
  c.result.t_final_max = horizon;
  c.spec.warm = nullptr;
  return c;
}

// A candidate as bytes, for the pipe from its worker process (same machine, same build). One field
// list (transfer) serves both directions, so writer and reader cannot disagree.
class Writer {
 public:
  template <typename T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    buf_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void text(const std::string& v) {
    value(v.size());
    buf_.append(v);
  }
  template <typename V>
  bool count(const V& v) {
    value(v.size());
    return true;
  }
  bool ok() const { return true; }
  const std::string& str() const { return buf_; }

 private:
  std::string buf_;
};

class Reader {
 public:
  explicit Reader(const std::string& buf) : buf_(buf) {}
  template <typename T>
  void value(T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (!ok_ || buf_.size() - at_ < sizeof v) {
      ok_ = false;
      return;
    }
    std::memcpy(&v, buf_.data() + at_, sizeof v);
    at_ += sizeof v;
  }
  void text(std::string& v) {
    std::size_t n = 0;
    value(n);
    if (!ok_ || buf_.size() - at_ < n) {
      ok_ = false;
      return;
    }
    v.assign(buf_, at_, n);
    at_ += n;
  }
  // Reads a length and sizes the container to it (at most 2^20 elements).
  template <typename V>
  bool count(V& v) {
    std::size_t n = 0;
    value(n);
    ok_ = ok_ && n <= static_cast<std::size_t>(1) << 20;
    if (ok_) v.resize(n);
    return ok_;
  }
  bool ok() const { return ok_ && at_ == buf_.size(); }

 private:
  const std::string& buf_;
  std::size_t at_{0};
  bool ok_{true};
};

template <typename Io, typename C>  // C: Candidate or const Candidate
void transfer(Io& io, C& c) {
  auto& r = c.result;
  io.value(r.ok);
  io.text(r.error);
  io.value(r.cost_ns);
  io.value(r.fuel_kg);
  io.value(r.t_final);
  io.value(r.t_final_min);
  io.value(r.t_final_max);
  io.value(r.nodes);
  io.value(r.t_active);
  io.value(r.iterations);
  io.value(r.solve_seconds);
  if (!io.count(r.samples)) return;
  for (auto& smp : r.samples) {
    io.value(smp.t);
    for (int k = 0; k < 3; ++k) io.value(smp.omega_d[k]);
    for (int k = 0; k < 3; ++k) io.value(smp.omega_d_dot[k]);
    for (int k = 0; k < 8; ++k) io.value(smp.u_d[k]);
  }
  auto& v = r.verification;
  io.value(v.passed);
  io.text(v.failure);
  io.value(v.max_defect);
  io.value(v.max_rate_excess);
  io.value(v.max_control_excess);
  io.value(v.boundary_error);
  io.value(v.propagation_error);
  io.value(v.propagated_final_rate);
  io.value(c.spec.nodes);
  if (!io.count(c.spec.grid)) return;
  for (auto& g : c.spec.grid) io.value(g);
  io.value(c.spec.t_min);
  io.value(c.spec.t_max);
  io.value(c.spec.rest_at_end);
}

std::string encode(const Candidate& c) {
  Writer w;
  transfer(w, c);
  return w.str();
}

bool decode(const std::string& bytes, Candidate& c) {
  Reader in(bytes);
  transfer(in, c);
  return in.ok();
}

// The candidates of a long horizon, in the order of `horizons`. With PlanSettings::jobs != 1 each is
// solved in a worker process of its own (fork; at most `jobs` at once, the longest horizons first,
// since they take longest); the workers share nothing, so the result is the same as one after the
// other. A worker that ends without a complete answer makes its candidate fail with the reason.
std::vector<Candidate> solve_candidates(const PlanProblem& problem,
                                        const std::vector<double>& horizons) {
  const std::size_t n = horizons.size();
  std::size_t jobs = problem.settings.jobs > 0
                         ? static_cast<std::size_t>(problem.settings.jobs)
                         : std::max<std::size_t>(1, std::thread::hardware_concurrency());
  jobs = std::min(jobs, n);
  std::vector<Candidate> out(n);
  if (jobs <= 1 || g_candidate_worker) {
    for (std::size_t i = 0; i < n; ++i) out[i] = solve_candidate(problem, horizons[i]);
    return out;
  }
  const auto failed = [&](std::size_t i, const std::string& why) {
    out[i] = Candidate{};
    out[i].result.t_final_max = horizons[i];
    out[i].result.error = why;
  };
  struct Worker {
    pid_t pid{-1};
    int fd{-1};
    std::size_t index{0};
    std::string bytes;
  };
  std::vector<Worker> running;
  std::size_t next = 0;  // horizons are increasing: start from the last
  std::fflush(nullptr);  // nothing buffered is written twice by a child
  while (next < n || !running.empty()) {
    while (running.size() < jobs && next < n) {
      const std::size_t i = n - 1 - next++;
      int fds[2];
      if (::pipe(fds) != 0) {
        failed(i, std::string("no pipe for a planner worker: ") + std::strerror(errno));
        continue;
      }
      const pid_t pid = ::fork();
      if (pid < 0) {
        ::close(fds[0]);
        ::close(fds[1]);
        failed(i, std::string("no planner worker process: ") + std::strerror(errno));
        continue;
      }
      if (pid == 0) {  // the worker: solve, write, leave without the parent's exit handlers
        ::close(fds[0]);
        g_candidate_worker = true;
        std::string bytes;
        try {
          bytes = encode(solve_candidate(problem, horizons[i]));
        } catch (...) {
          ::_exit(2);
        }
        std::size_t at = 0;
        while (at < bytes.size()) {
          const ssize_t w = ::write(fds[1], bytes.data() + at, bytes.size() - at);
          if (w < 0 && errno == EINTR) continue;
          if (w <= 0) ::_exit(3);
          at += static_cast<std::size_t>(w);
        }
        ::_exit(0);
      }
      ::close(fds[1]);
      running.push_back(Worker{pid, fds[0], i, {}});
    }
    if (running.empty()) continue;
    std::vector<pollfd> polls;
    for (const Worker& w : running) polls.push_back(pollfd{w.fd, POLLIN, 0});
    if (::poll(polls.data(), polls.size(), -1) < 0 && errno != EINTR) {
      for (Worker& w : running) {  // cannot wait on them: stop them, their candidates fail
        ::kill(w.pid, SIGKILL);
        ::close(w.fd);
        ::waitpid(w.pid, nullptr, 0);
        failed(w.index, std::string("planner worker lost: poll: ") + std::strerror(errno));
      }
      running.clear();
      continue;
    }
    for (std::size_t k = polls.size(); k-- > 0;) {
      if (polls[k].revents == 0) continue;
      Worker& w = running[k];
      char chunk[65536];
      const ssize_t got = ::read(w.fd, chunk, sizeof chunk);
      if (got > 0) {
        w.bytes.append(chunk, static_cast<std::size_t>(got));
        continue;
      }
      if (got < 0 && errno == EINTR) continue;
      ::close(w.fd);  // end of the worker's answer
      int status = 0;
      while (::waitpid(w.pid, &status, 0) < 0 && errno == EINTR) {
      }
      if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0 && decode(w.bytes, out[w.index]))) {
        std::ostringstream why;
        why << "the planner worker for the " << horizons[w.index] << " s horizon ended without a "
            << "complete plan (";
        if (WIFSIGNALED(status)) {
          why << "signal " << WTERMSIG(status);
        } else {
          why << "exit status " << WEXITSTATUS(status) << ", " << w.bytes.size() << " bytes";
        }
        why << ")";
        failed(w.index, why.str());
      }
      running.erase(running.begin() + static_cast<std::ptrdiff_t>(k));
    }
  }
  return out;
}

// Long horizon [Rocksteady choice] (PlanSettings::active_horizon_max): the least-fuel verified plan
// among the horizons t_auto, 2 t_auto, ... up to `active` (each solved cold: a warm start from the
// shorter plan extended by rest stays in its local minimum, measured on cases 4 and 7), ending with
// u_d = 0, then rest to t_final: two more samples, omega_d = 0 and u_d = 0 (Eq. 41 holds exactly
// there; none when the chosen despin already ends at t_final). The whole plan is verified again, rest
// tail included.
PlanResult plan_long(const PlanProblem& problem, double t_auto, double active, double t_final) {
  // Doubling from t_auto up to `active`, and `active` itself when the last doubling is more than
  // 25 % short of it.
  std::vector<double> horizons;
  for (double h = t_auto; h <= active; h *= 2.0) horizons.push_back(h);
  if (horizons.empty() || horizons.back() < active / 1.25) horizons.push_back(active);
  // Every candidate is solved and verified (verify_samples) without the grid-refinement re-solve;
  // then the cheapest is refinement-checked, and, should that fail, the next cheapest, and so on:
  // the re-solves of the candidates that lose are saved.
  std::vector<Candidate> candidates;
  int iterations = 0;
  int refined_iterations = 0;
  double seconds = 0.0;
  double refined_seconds = 0.0;
  std::string failures;
  const auto note = [&failures](double h, const std::string& why) {
    std::ostringstream msg;
    msg << (failures.empty() ? "" : "; ") << h << " s: " << why;
    failures += msg.str();
  };
  for (Candidate& c : solve_candidates(problem, horizons)) {
    iterations += c.result.iterations;
    seconds += c.result.solve_seconds;
    if (c.result.ok) {
      candidates.push_back(std::move(c));
    } else {
      note(c.result.t_final_max, c.result.error);
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.result.fuel_kg < b.result.fuel_kg;
  });
  PlanResult r;
  for (Candidate& c : candidates) {
    if (!problem.settings.verify_refinement) {
      r = std::move(c.result);
      break;
    }
    const bool passed = check_refinement(problem.model, problem.settings, c.spec, c.result);
    refined_iterations += c.result.verification.refined_iterations;
    refined_seconds += c.result.verification.refined_seconds;
    if (passed) {
      r = std::move(c.result);
      break;
    }
    note(c.result.t_final, c.result.error);
  }
  r.iterations = iterations;
  r.solve_seconds = seconds;
  r.verification.refined_iterations = refined_iterations;
  r.verification.refined_seconds = refined_seconds;
  r.t_final_min = t_final;
  r.t_final_max = t_final;
  if (!r.ok) {
    r.error = "no active horizon up to " + std::to_string(active) + " s gave a verified plan (" +
              failures + ")";
    return r;
  }
  if (r.samples.size() + 2 > static_cast<std::size_t>(gnc::kMaxTrajectorySamples)) {
    r.ok = false;
    r.error = "the active plan fills the on-board table: no room for the rest tail";
    return r;
  }
  r.t_active = r.t_final;
  if (r.t_active < t_final) {
    PlanSample mid;
    mid.t = 0.5 * (r.t_active + t_final);
    PlanSample end;
    end.t = t_final;
    r.samples.push_back(mid);
    r.samples.push_back(end);
    r.t_final = t_final;
    r.nodes += 1;
  }
  const Verification active_v = r.verification;
  r.verification = verify_samples(problem.model, r.samples, problem.settings.propagation_limit);
  r.verification.refinement_checked = active_v.refinement_checked;
  r.verification.refined_nodes = active_v.refined_nodes;
  r.verification.refined_fuel_kg = active_v.refined_fuel_kg;
  r.verification.refinement_change = active_v.refinement_change;
  r.verification.refined_iterations = active_v.refined_iterations;
  r.verification.refined_seconds = active_v.refined_seconds;
  if (!r.verification.passed) {
    r.ok = false;
    r.error = "verification failed (rest tail): " + r.verification.failure;
  }
  return r;
}

}  // namespace

PlanResult plan(const PlanProblem& problem) { return plan_impl(problem, false); }

namespace {

PlanResult plan_impl(const PlanProblem& problem, bool rest_at_end, SolveSpec* grid_out) {
  PlanResult r;
  const PlanModel& model = problem.model;
  const PlanSettings& settings = problem.settings;
  try {
    check_model(model, settings.nodes > 0 ? settings.nodes : kDefaultNodes);
  } catch (const std::invalid_argument& e) {
    r.error = std::string("invalid problem: ") + e.what();
    return r;
  }
  resolve_final_time_bounds(model, settings, r.t_final_min, r.t_final_max);
  if (!(r.t_final_max >= r.t_final_min)) {
    r.error = "invalid problem: t_final_max < t_final_min";
    return r;
  }
  if (!settings.free_final_time && !settings.tumble_grid && settings.nodes <= 0 &&
      settings.active_horizon_max >= 0.0) {
    PlanSettings automatic = settings;
    automatic.t_final_max = 0.0;
    double t_auto_min = 0.0;
    double t_auto = 0.0;
    resolve_final_time_bounds(model, automatic, t_auto_min, t_auto);
    const bool automatic_active = settings.active_horizon_max <= 0.0;
    const double active =
        automatic_active ? std::max(t_auto, std::min(kActiveHorizon, kActiveFactor * t_auto))
                         : settings.active_horizon_max;
    const double full_up_to = automatic_active ? std::min(active, kFullFactor * t_auto) : active;
    if (r.t_final_max > full_up_to) {
      return plan_long(problem, t_auto, std::min(active, r.t_final_max), r.t_final_max);
    }
  }
  SolveSpec spec;
  spec.t_min = r.t_final_min;
  spec.t_max = r.t_final_max;
  spec.rest_at_end = rest_at_end;
  if (problem.warm_start != nullptr && problem.warm_start->size() >= 3) {
    spec.warm = problem.warm_start;
    spec.warm_mu = kWarmMu;
  }
  if (settings.tumble_grid) {
    // Pass 1: a grid that follows an a-priori tumble (the momentum-ramp guess's rate).
    const double w0 = model.omega_init.norm();
    const double t_f = 0.5 * (r.t_final_min + r.t_final_max);
    spec.grid = tumble_grid(
        [&](double t) { return w0 * std::max(1.0 - t / t_f, kTumbleFloor); }, t_f,
        settings.intervals_per_turn, settings.nodes, max_nodes());
  } else {
    if (settings.nodes <= 0 && std::ceil(r.t_final_max / kUniformStep) + 1.0 > max_nodes()) {
      // Refused before solving: at the grid's resolution the plan would not fit the on-board
      // table, and a coarser grid fails the open-loop check (after minutes of solving).
      std::ostringstream msg;
      msg << "invalid problem: a " << r.t_final_max << " s horizon needs "
          << std::ceil(r.t_final_max / kUniformStep) + 1.0 << " nodes at one per " << kUniformStep
          << " s; the on-board table holds " << max_nodes()
          << " (at most " << kUniformStep * (max_nodes() - 1)
          << " s on the uniform grid; try the tumble-following grid)";
      r.error = msg.str();
      return r;
    }
    spec.grid = uniform_grid(settings.nodes > 0 ? settings.nodes
                                                : automatic_uniform_nodes(r.t_final_max));
  }
  spec.nodes = static_cast<int>(spec.grid.size());
  SolveOutcome main = solve(model, settings, spec);
  r.iterations = main.iterations;
  r.solve_seconds = main.seconds;
  // Mesh refinement (automatic grid): re-grid on the plan's own interval errors and re-solve,
  // warm-started, until the open-loop check holds (at most kMaxRegrids times). The error target
  // tightens each round, since the global error is not just the sum of the local ones.
  const double limit = settings.propagation_limit * model.omega_init.norm();
  double safety = kRegridSafety;
  for (int round = 0; main.ok && settings.tumble_grid && settings.nodes <= 0 && round < kMaxRegrids;
       ++round) {
    const std::vector<double> err = interval_errors(model, main.samples);
    if (round > 0 && verify_samples(model, main.samples, settings.propagation_limit).passed) break;
    const std::vector<PlanSample> previous = main.samples;
    SolveSpec again = spec;
    again.grid = error_grid(previous, err, safety * limit, kFloorIntervalsPerTurn, max_nodes());
    again.nodes = static_cast<int>(again.grid.size());
    again.warm = &previous;
    again.warm_mu = kWarmMu;
    SolveOutcome next = solve(model, settings, again);
    r.iterations += next.iterations;
    r.solve_seconds += next.seconds;
    main = std::move(next);
    spec = again;
    spec.warm = nullptr;
    safety *= 0.25;
  }
  // Automatic uniform grid: when the open-loop check fails (faster dynamics than case 1's, e.g. a
  // larger u_max), 1.5x the nodes, warm-started, while the table holds them.
  for (int round = 0; main.ok && !settings.tumble_grid && settings.nodes <= 0 &&
                      spec.nodes < max_nodes() && round < kMaxRegrids;
       ++round) {
    if (verify_samples(model, main.samples, settings.propagation_limit).passed) break;
    const std::vector<PlanSample> previous = main.samples;
    SolveSpec again = spec;
    again.grid = uniform_grid(std::min(max_nodes(), (3 * spec.nodes) / 2));
    again.nodes = static_cast<int>(again.grid.size());
    again.warm = &previous;
    again.warm_mu = kWarmMu;
    SolveOutcome next = solve(model, settings, again);
    r.iterations += next.iterations;
    r.solve_seconds += next.seconds;
    main = std::move(next);
    spec = again;
    spec.warm = nullptr;
  }
  r.nodes = spec.nodes;
  if (!main.ok) {
    r.error = main.error;
    return r;
  }
  r.cost_ns = main.cost_ns;
  r.fuel_kg = main.cost_ns / (kIsp * kG0);  // Eq. (54)
  r.t_final = main.t_final;
  r.t_active = main.t_final;
  r.samples = std::move(main.samples);
  r.verification = verify_samples(model, r.samples, settings.propagation_limit);
  if (!r.verification.passed) {
    r.error = "verification failed: " + r.verification.failure;
    return r;
  }
  if (grid_out != nullptr) *grid_out = spec;
  if (settings.verify_refinement && !check_refinement(model, settings, spec, r)) return r;
  r.ok = true;
  return r;
}

}  // namespace

gnc::TrajectoryTable to_table(const std::vector<PlanSample>& samples) {
  if (samples.size() > static_cast<std::size_t>(gnc::kMaxTrajectorySamples)) {
    throw std::length_error("plan has more samples than the on-board trajectory table holds");
  }
  gnc::TrajectoryTable table;
  table.count = static_cast<int>(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    table.samples[i].t = samples[i].t;
    table.samples[i].omega_d = samples[i].omega_d;
    table.samples[i].omega_d_dot = samples[i].omega_d_dot;
  }
  if (table.count > 0) table.samples[table.count - 1].omega_d = Vec3::Zero();
  table.checksum = gnc::trajectory_checksum(table);
  return table;
}

std::vector<PlanSample> remaining_plan(const std::vector<PlanSample>& samples, double t_now) {
  std::vector<PlanSample> out;
  if (samples.size() < 3 || !(t_now < samples.back().t)) return out;
  // First node at or after t_now; the point at t_now interpolated in front of it.
  std::size_t k = 0;
  while (k < samples.size() && samples[k].t < t_now) k += 2;
  if (k >= samples.size()) return out;
  PlanSample first;
  if (k == 0) {
    first = samples[0];
  } else {
    const PlanSample& a = samples[k - 2];
    const PlanSample& b = samples[k];
    const double s = (t_now - a.t) / (b.t - a.t);
    first.omega_d = (1 - s) * a.omega_d + s * b.omega_d;
    first.omega_d_dot = (1 - s) * a.omega_d_dot + s * b.omega_d_dot;
    first.u_d = (1 - s) * a.u_d + s * b.u_d;
  }
  first.t = t_now;
  out.push_back(first);
  if (k > 0 && samples[k].t > t_now) {  // a midpoint between t_now and node k
    PlanSample m;
    m.t = 0.5 * (t_now + samples[k].t);
    m.omega_d = 0.5 * (first.omega_d + samples[k].omega_d);
    m.omega_d_dot = 0.5 * (first.omega_d_dot + samples[k].omega_d_dot);
    m.u_d = 0.5 * (first.u_d + samples[k].u_d);
    out.push_back(m);
  }
  for (std::size_t i = k == 0 ? 1 : k; i < samples.size(); ++i) out.push_back(samples[i]);
  if (out.size() % 2 == 0) out.erase(out.begin() + 1);  // first and node k coincide
  for (PlanSample& p : out) p.t -= t_now;
  out.front().t = 0.0;
  return out;
}

PlanModel replan_model(const gnc::GncParams& active, const Vec3& omega_hat) {
  PlanModel m;
  m.j_hat = gnc::total_inertia(active.mass_hat);
  m.b_hat = gnc::torque_matrix(active.rcs, active.mass_hat.r_so_bcm);
  m.u_max = active.rcs.u_max;
  m.eps_trans = active.guidance.eps_trans;
  m.omega_init = omega_hat;
  return m;
}

PlanModel study_case_model(double u_max, double delta_j_norm, double delta_r_norm) {
  gnc::MassProperties mp = gnc::study_true_mass_properties();
  mp.j_ast -= delta_j_norm * Vec3(-1.0, 1.0, 0.5).asDiagonal().toDenseMatrix();  // SPEC §5
  mp.r_so_bcm -= delta_r_norm * Vec3(1.0, 1.0, 1.0) / std::sqrt(3.0);
  PlanModel m;
  m.j_hat = gnc::total_inertia(mp);
  m.b_hat = gnc::torque_matrix(gnc::study_rcs_layout(u_max), mp.r_so_bcm);
  m.u_max = u_max;
  m.eps_trans = 0.5 * 2.0 * 3.14159265358979323846 / 60.0;  // 0.5 rpm
  m.omega_init = Vec3(0.01, 0.02, 0.03);
  return m;
}

namespace {
void hash_bytes(std::uint64_t& h, const void* data, std::size_t n) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= bytes[i];
    h *= 1099511628211ULL;
  }
}
void hash_double(std::uint64_t& h, double v) { hash_bytes(h, &v, sizeof v); }
}  // namespace

std::uint64_t problem_hash(const PlanProblem& problem) {
  std::uint64_t h = 14695981039346656037ULL;
  const PlanModel& m = problem.model;
  const PlanSettings& s = problem.settings;
  const char tag[] = "rocksteady-plan-v3";
  hash_bytes(h, tag, sizeof tag);
  for (int i = 0; i < 9; ++i) hash_double(h, m.j_hat(i / 3, i % 3));
  for (int i = 0; i < 24; ++i) hash_double(h, m.b_hat(i / 8, i % 8));
  hash_double(h, m.u_max);
  hash_double(h, m.eps_trans);
  for (int i = 0; i < 3; ++i) hash_double(h, m.omega_init[i]);
  const std::int64_t nodes = s.nodes;
  hash_bytes(h, &nodes, sizeof nodes);
  hash_double(h, s.t_final_min);
  hash_double(h, s.t_final_max);
  hash_double(h, s.tolerance);
  hash_double(h, s.refinement_limit);
  hash_double(h, s.propagation_limit);
  const bool bisect = s.refinement_check == PlanSettings::RefinementCheck::kBisect;
  const std::int64_t flags = (s.verify_refinement ? 1 : 0) + (s.free_final_time ? 2 : 0) +
                             (bisect ? 4 : 0) +
                             (s.tumble_grid ? 8 : 0) + 16 * std::int64_t{s.max_iterations};
  hash_double(h, s.intervals_per_turn);
  hash_double(h, s.active_horizon_max);
  hash_bytes(h, &flags, sizeof flags);
  return h;
}

}  // namespace rocksteady::ground::planner
