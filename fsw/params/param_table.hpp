// The GNC parameter table, cFS style: loads go into an inactive copy, the whole copy is validated
// with gnc::validate (the first bad field is the reason), and an activation swaps it in at a tick
// boundary (the application calls gnc::Gnc::set_params there). The active table lives in the
// flight core (gnc::Gnc::params()).
#pragma once

#include <array>
#include <cstdint>

#include "fsw/interface.hpp"
#include "gnc/params.hpp"

namespace rocksteady::fsw {

// Loadable parameters: the gains and thresholds of gnc::GncParams. The GNC period, the mass
// properties and the RCS layout are configuration, not ground-loadable. Stable numbers (uplinked).
enum class ParamId : std::int32_t {
  kNtclK = 0,
  kNtclLambda = 1,
  kElK = 2,
  kElLambda = 3,
  kFeedforwardK = 4,
  kFeedforwardLambda = 5,
  kIntegralK = 6,
  kIntegralLambda = 7,
  kIntegralKi = 8,
  kIntegralLimit = 9,
  kAdaptiveK = 10,
  kAdaptiveLambda = 11,
  kAdaptiveGamma = 12,
  kAdaptiveEigFloor = 13,
  kAdaptiveEigCeiling = 14,
  kSo3K = 15,
  kSo3Lambda = 16,
  kDpdKd = 17,
  kDpdKp = 18,
  kOmegaSwitch = 19,
  kKqd = 20,
  kEpsTrans = 21,
  kTrackResetPeriod = 22,
  kSensorTimeout = 23,
  kAutoHold = 24,
  kGyroMaxRate = 25,
  kQuatNormTolerance = 26,
  kEstimatorOmegaC = 27,
};
inline constexpr int kParamCount = 28;

// kMatrix: 3 values (diagonal) or 6 values (symmetric: xx, yy, zz, xy, xz, yz).
// kScalar: 1 value. kFlag: 1 value, 0 or 1.
enum class ParamKind : std::uint8_t { kMatrix, kScalar, kFlag };

struct ParamSpec {
  ParamId id;
  const char* name;
  ParamKind kind;
  const char* units;  // for the ground's read-back (rocksteady-ground params get)
};
const std::array<ParamSpec, kParamCount>& param_specs();

struct ParamLoadResult {
  RejectReason reason{RejectReason::kNone};
  std::int32_t detail{0};
  const char* text{""};  // the first bad field (gnc::validate) or the range problem
  const char* why{""};   // gnc::validate's reason for that field
  bool ok() const { return reason == RejectReason::kNone; }
};

// Writes `n` values of parameter `id` into `table` (no validation of the whole table).
ParamLoadResult write_param(gnc::GncParams& table, std::int32_t id, const double* values, int n);
// The inverse: parameter `id` of `table` into `values` (a matrix as 6 values xx yy zz xy xz yz, a
// scalar or flag as 1); returns the number of values, 0 for an unknown id.
int read_param(const gnc::GncParams& table, std::int32_t id, double* values);

class ParamTable {
 public:
  // inactive := active, nothing loaded, nothing staged.
  void reset(const gnc::GncParams& active);

  // Loads into a copy of the inactive table and validates the whole copy; only a valid copy
  // becomes the inactive table (the inactive table is always valid).
  ParamLoadResult load(std::int32_t id, const double* values, int n);
  // The same for a whole model: J_tot, r_SO/BCM and thruster strengths (gnc::with_model).
  ParamLoadResult load_model(const gnc::Mat3& j_tot, const gnc::Vec3& r, const gnc::Vec16& k);
  bool loaded() const { return loaded_; }
  const gnc::GncParams& inactive() const { return inactive_; }

  // Snapshot of the inactive table for activation at the next tick boundary (false: nothing
  // loaded).
  bool stage();
  bool staged() const { return staged_; }
  const gnc::GncParams& staged_table() const { return staged_table_; }
  // The staged table is now active: later loads (made after the snapshot) stay in the inactive
  // copy, otherwise inactive := active.
  void activated(const gnc::GncParams& active);
  // The activation failed at the boundary: nothing changes but the stage.
  void activation_failed() { staged_ = false; }
  // Drop the loads: inactive := active.
  void discard(const gnc::GncParams& active);

 private:
  gnc::GncParams inactive_{};
  gnc::GncParams scratch_{};
  gnc::GncParams staged_table_{};
  bool loaded_{false};
  bool staged_{false};
  std::uint32_t loads_{0};
  std::uint32_t loads_at_stage_{0};
};

}  // namespace rocksteady::fsw
