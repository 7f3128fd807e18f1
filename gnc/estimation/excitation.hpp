// Identification excitation (gnc/estimation/README.md §I.6, Eqs. X1-X6): a deliberate net force
// added to the allocator's channel forces in the null space of the model's torque map B_hat, so it
// makes no torque on the current model (the control law is not disturbed), while a wrong r_hat
// turns it into the torque (r - r_hat) x F that the identifier needs to see r (§I.3 item 2).
//
// Per physical channel c the "+" thruster pushes along d_c, so the channels' net force is E u with
// E = [d_0 ... d_7] (3x8). The excitation is
//   Delta u = N F + Z z,   [B_hat; E] N = [0; I3],   [B_hat; E] Z = 0          (X2)
// N is the minimum-norm right inverse's force block and Z (8x2) an orthonormal basis of the
// kernel of M = [B_hat; E] (rank 6 for the SPEC §4 layout). z = 0 unless a channel already sits at
// its bound and Delta u would push it further: then z removes that channel (up to two) from the
// excitation (X4), and a last scale gamma in [0, 1] keeps every channel in its box (X5).
// The force F cycles through +x, -x, +y, -y, +z, -z (F_B), one direction per identification
// window (X3): every component of r is normal to four of the six, and a constant unmodelled
// torque (a gyro bias's gyroscopic term, a disturbance) cancels between a window and the next.
//
// (X7) With r_sigma_target_m > 0 the amplitudes are scaled per window to what (X6) needs for that
// 1 sigma of r given the identifier's window noise: quiet gyros fly a tenth of noisy ones' force.
//
// (X8) The inertia phase, before start_after_s of identification: r_hat is still up to 1 m off, so
// any net force turns into a torque (r - r_hat) x F that the first windows would fit into J. The
// allocated forces are made force-free instead, and a pure couple is added:
//   Delta u = C tau - N (E u),   [B_hat; E] C = [I3; 0]                       (X8)
// so E (u + Delta u) = 0 and B_hat (u + Delta u) = B_hat u + tau on the model. With the
// pseudoinverse's u (in the row space of B_hat) u + Delta u is the minimum-norm force-free
// allocation of the law's torque plus tau. tau cycles +x, -x, +y, -y, +z, -z (F_B), one per window,
// at inertia_torque_nm per axis: the law's own torque lies along -omega, and a torque along other
// axes is what shows J's columns in two windows instead of six.
//
// N, C and Z depend only on B_hat and E: they are computed once per model change, spread over
// kModelStages ticks (set_model, then step_model once a tick); the excitation stays off until
// they are ready. Per tick: 24 multiply-adds for N F, a scan of the eight channels and eight
// divisions for gamma (a 2x2 solve more when the allocation saturates).
//
// Flight code: fixed-size Eigen, no heap, no exceptions, no I/O.
#pragma once

#include <cstdint>

#include "gnc/model/rcs.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

using Mat82 = Eigen::Matrix<double, kChannels, 2>;

struct ExcitationConfig {
  bool enabled{false};          // off for the study's strategies
  // Amplitude of F along each body axis, N (X6 sizes it); an axis at 0 is left out of the cycle.
  Vec3 force_n{100.0, 100.0, 400.0};
  double duration_s{600.0};     // at most this long in all (s of excitation)
  double r_sigma_stop_m{0.005}; // stop once every 1 sigma of r_hat is below this (and none unobservable)
  // Start only after this much identification (closed windows times their length, s): the first
  // windows, with r_hat still up to 1 m off, would fit the excitation's torque into J (README §I.6).
  double start_after_s{0.0};
  // (X7) 0: force_n is flown as given. > 0: force_n is the largest amplitude, and each window flies
  // force_n * s with the s that (X6) needs for this 1 sigma of r over duration_s of excitation,
  // given the identifier's window noise (at most 1): quiet sensors need a fraction of the force
  // that noisy ones do (README §I.6).
  double r_sigma_target_m{0.0};
  // (X8) The inertia phase before start_after_s: the allocation made force-free, plus a couple of
  // this amplitude per body axis (N m), cycled +x, -x, +y, -y, +z, -z one per window (an axis at
  // 0 is left out of the cycle). 0 on every axis: no inertia phase.
  Vec3 inertia_torque_nm{Vec3::Zero()};
};

struct ExcitationConfigCheck {
  bool ok{true};
  const char* field{""};
  const char* reason{""};
};
ExcitationConfigCheck validate(const ExcitationConfig& c);

// What one tick's excitation did.
struct ExcitationStatus {
  bool active{false};          // the excitation was asked for this tick
  bool inertia{false};         // (X8) the inertia phase: force nulled, a couple added
  Vec3 force{Vec3::Zero()};    // net force asked, N (F_B); in the inertia phase the one nulled
  Vec3 torque{Vec3::Zero()};   // (X8) couple asked, N m (F_B), before gamma
  double gamma{0.0};           // the fraction that fitted the channels' box (X5)
  std::uint8_t blocked{0};     // channels removed from the excitation at their bound (X4)
};

class IdentificationExcitation {
 public:
  static constexpr int kModelStages = 6;
  static constexpr int kDirections = 6;

  // New settings; the excitation time already spent is kept (restart() clears it).
  void configure(const ExcitationConfig& c);
  const ExcitationConfig& config() const { return config_; }
  // A new model (B_hat of the active table, the layout's channel directions): N and Z are
  // recomputed over the next kModelStages calls of step_model(); until then ready() is false.
  void set_model(const Mat38& b_hat, const RcsLayout& rcs);
  // One stage of the model computation (no-op once ready). Call once a tick.
  void step_model();
  bool ready() const { return stage_ == kModelStages && valid_; }
  // Whether the excitation should run: enabled, model ready, at least start_after_s of
  // identification done (identified_s), less than duration_s spent, and r not yet known to
  // r_sigma_stop_m in every direction (max_r_sigma: largest 1 sigma of r_hat; unobservable:
  // directions of r the data have not shown).
  bool wanted(double max_r_sigma, int unobservable, double identified_s) const;
  // (X7) Sizes the amplitude to the window noise: rho, the variance of one row of the
  // identifier's window equation ((N m s)^2, I5), for windows of window_s. With
  // r_sigma_target_m > 0, s = min(1, sqrt(4 n rho / (D T sigma^2 min_a sum_{b != a} f_b^2))), n the
  // axes in the cycle, D = duration_s, T = window_s, f = force_n; otherwise (or when rho or T is
  // not a positive finite number) s = 1. A few multiplies and a square root.
  void size_to_window_noise(double rho, double window_s);
  double amplitude_scale() const { return scale_; }
  // The force of window `window_index` (X3): +x, -x, +y, -y, +z, -z with the axes' amplitudes
  // (axes at zero amplitude skipped), times amplitude_scale() (X7).
  Vec3 force(std::uint32_t window_index) const;
  // Adds the excitation for net force f to the allocated channel forces u (effective force, as
  // B_hat multiplies) within lo <= u <= hi (X4, X5), and counts dt of excitation time. Returns
  // what was done; u is unchanged when !ready().
  ExcitationStatus apply(const Vec3& f, const Vec8& lo, const Vec8& hi, double dt, Vec8& u);
  // (X8) Whether the inertia phase should run: enabled, model ready, a couple configured, and
  // less than start_after_s of identification done (identified_s). Gnc flies it in DETUMBLE only.
  bool inertia_wanted(double identified_s) const;
  // The couple of window `window_index` (X8): +x, -x, +y, -y, +z, -z at inertia_torque_nm.
  Vec3 inertia_torque(std::uint32_t window_index) const;
  // (X8) Nulls the net force of the allocated channel forces u and adds the couple tau, within
  // lo <= u <= hi (X4, X5 as for apply), and counts dt of inertia-phase time. u is unchanged when
  // !ready().
  ExcitationStatus apply_inertia(const Vec3& tau, const Vec8& lo, const Vec8& hi, double dt, Vec8& u);
  double inertia_elapsed() const { return inertia_elapsed_; }
  // Seconds of excitation spent so far.
  double elapsed() const { return elapsed_; }
  // Back to no excitation spent (a declared change: r must be learned again).
  void restart() { elapsed_ = 0.0; }

  const Mat83& force_map() const { return n_; }  // N of (X2)
  const Mat82& kernel() const { return z_; }     // Z of (X2)
  const Mat83& couple_map() const { return c_; } // C of (X8)

 private:
  ExcitationConfig config_{};
  Eigen::Matrix<double, 6, kChannels> m_{Eigen::Matrix<double, 6, kChannels>::Zero()};
  Eigen::Matrix<double, 6, 6> g_{Eigen::Matrix<double, 6, 6>::Zero()};      // G = M M'
  Eigen::Matrix<double, 6, 6> g_inv_{Eigen::Matrix<double, 6, 6>::Zero()};  // G^-1
  Eigen::Matrix<double, 6, kChannels> h_{Eigen::Matrix<double, 6, kChannels>::Zero()};  // G^-1 M
  Eigen::Matrix<double, kChannels, kChannels> p_{
      Eigen::Matrix<double, kChannels, kChannels>::Zero()};  // I - M'(MM')^-1 M
  Mat83 n_{Mat83::Zero()};
  Mat83 c_{Mat83::Zero()};
  Mat82 z_{Mat82::Zero()};
  Vec3 directions_[kDirections]{};
  int n_directions_{0};
  Vec3 couples_[kDirections]{};  // (X8)
  int n_couples_{0};
  double inertia_elapsed_{0.0};
  // (X4, X5) fits du into the channels' box and adds it to u; fills blocked and gamma.
  void fit(Vec8 du, const Vec8& lo, const Vec8& hi, Vec8& u, ExcitationStatus& s) const;
  double min_pair_{0.0};  // min over the cycle's axes a of sum_{b != a} f_b^2 (X7), N^2
  double scale_{1.0};     // (X7)
  int stage_{kModelStages};
  bool valid_{false};
  double elapsed_{0.0};
};

}  // namespace rocksteady::gnc
