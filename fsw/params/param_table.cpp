#include "fsw/params/param_table.hpp"

#include <cmath>

namespace rocksteady::fsw {

namespace {

constexpr std::array<ParamSpec, kParamCount> kSpecs{{
    {ParamId::kNtclK, "ntcl.K", ParamKind::kMatrix, "N m s"},
    {ParamId::kNtclLambda, "ntcl.Lambda", ParamKind::kMatrix, "1/s"},
    {ParamId::kElK, "el.K", ParamKind::kMatrix, "N m s"},
    {ParamId::kElLambda, "el.Lambda", ParamKind::kMatrix, "1/s"},
    {ParamId::kFeedforwardK, "feedforward.K", ParamKind::kMatrix, "N m s"},
    {ParamId::kFeedforwardLambda, "feedforward.Lambda", ParamKind::kMatrix, "1/s"},
    {ParamId::kIntegralK, "integral.K", ParamKind::kMatrix, "N m s"},
    {ParamId::kIntegralLambda, "integral.Lambda", ParamKind::kMatrix, "1/s"},
    {ParamId::kIntegralKi, "integral.K_I", ParamKind::kMatrix, "N m/rad"},
    {ParamId::kIntegralLimit, "integral.integral_limit", ParamKind::kScalar, "N m"},
    {ParamId::kAdaptiveK, "adaptive.K", ParamKind::kMatrix, "N m s"},
    {ParamId::kAdaptiveLambda, "adaptive.Lambda", ParamKind::kMatrix, "1/s"},
    {ParamId::kAdaptiveGamma, "adaptive.Gamma", ParamKind::kScalar, "(adaptation gain)"},
    {ParamId::kAdaptiveEigFloor, "adaptive.eig_floor_ratio", ParamKind::kScalar, ""},
    {ParamId::kAdaptiveEigCeiling, "adaptive.eig_ceiling_ratio", ParamKind::kScalar, ""},
    {ParamId::kSo3K, "so3.K", ParamKind::kMatrix, "N m s"},
    {ParamId::kSo3Lambda, "so3.Lambda", ParamKind::kMatrix, "1/s"},
    {ParamId::kDpdKd, "dpd.K_d", ParamKind::kMatrix, "N m s"},
    {ParamId::kDpdKp, "dpd.k_p", ParamKind::kScalar, "1/s"},
    {ParamId::kOmegaSwitch, "guidance.omega_switch", ParamKind::kScalar, "rad/s"},
    {ParamId::kKqd, "guidance.k_qd", ParamKind::kScalar, "1/s"},
    {ParamId::kEpsTrans, "guidance.eps_trans", ParamKind::kScalar, "rad/s"},
    {ParamId::kTrackResetPeriod, "guidance.track_reset_period", ParamKind::kScalar, "s"},
    {ParamId::kSensorTimeout, "mode.sensor_timeout", ParamKind::kScalar, "s"},
    {ParamId::kAutoHold, "mode.auto_hold", ParamKind::kFlag, "(flag)"},
    {ParamId::kGyroMaxRate, "estimator.gyro_max_rate", ParamKind::kScalar, "rad/s"},
    {ParamId::kQuatNormTolerance, "estimator.quat_norm_tolerance", ParamKind::kScalar, ""},
    {ParamId::kEstimatorOmegaC, "estimator.omega_c", ParamKind::kScalar, "rad/s"},
}};

constexpr bool specs_in_id_order() {
  for (int i = 0; i < kParamCount; ++i) {
    if (static_cast<int>(kSpecs[i].id) != i) return false;
  }
  return true;
}
static_assert(specs_in_id_order(), "parameter specs must be indexed by id");

template <class Params> auto matrix_field(Params& p, ParamId id) -> decltype(&p.ntcl.k) {
  switch (id) {
    case ParamId::kNtclK:
      return &p.ntcl.k;
    case ParamId::kNtclLambda:
      return &p.ntcl.lambda;
    case ParamId::kElK:
      return &p.el.k;
    case ParamId::kElLambda:
      return &p.el.lambda;
    case ParamId::kFeedforwardK:
      return &p.feedforward.k;
    case ParamId::kFeedforwardLambda:
      return &p.feedforward.lambda;
    case ParamId::kIntegralK:
      return &p.integral.k;
    case ParamId::kIntegralLambda:
      return &p.integral.lambda;
    case ParamId::kIntegralKi:
      return &p.integral.k_i;
    case ParamId::kAdaptiveK:
      return &p.adaptive.k;
    case ParamId::kAdaptiveLambda:
      return &p.adaptive.lambda;
    case ParamId::kSo3K:
      return &p.so3.k;
    case ParamId::kSo3Lambda:
      return &p.so3.lambda;
    case ParamId::kDpdKd:
      return &p.dpd.k_d;
    default:
      return nullptr;
  }
}

template <class Params> auto scalar_field(Params& p, ParamId id) -> decltype(&p.dpd.k_p) {
  switch (id) {
    case ParamId::kIntegralLimit:
      return &p.integral.integral_limit_nm;
    case ParamId::kAdaptiveGamma:
      return &p.adaptive.gamma;
    case ParamId::kAdaptiveEigFloor:
      return &p.adaptive.eig_floor_ratio;
    case ParamId::kAdaptiveEigCeiling:
      return &p.adaptive.eig_ceiling_ratio;
    case ParamId::kDpdKp:
      return &p.dpd.k_p;
    case ParamId::kOmegaSwitch:
      return &p.guidance.omega_switch;
    case ParamId::kKqd:
      return &p.guidance.k_qd;
    case ParamId::kEpsTrans:
      return &p.guidance.eps_trans;
    case ParamId::kTrackResetPeriod:
      return &p.guidance.track_reset_period_s;
    case ParamId::kSensorTimeout:
      return &p.mode.sensor_timeout_s;
    case ParamId::kGyroMaxRate:
      return &p.estimator.gyro_max_rate;
    case ParamId::kQuatNormTolerance:
      return &p.estimator.quat_norm_tolerance;
    case ParamId::kEstimatorOmegaC:
      return &p.estimator.omega_c;
    default:
      return nullptr;
  }
}

}  // namespace

const std::array<ParamSpec, kParamCount>& param_specs() {
  return kSpecs;
}

ParamLoadResult write_param(gnc::GncParams& table, std::int32_t id, const double* values, int n) {
  if (id < 0 || id >= kParamCount) {
    return ParamLoadResult{RejectReason::kOutOfRange, 0, "unknown parameter id"};
  }
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(values[i])) {
      return ParamLoadResult{RejectReason::kArgNotFinite, i + 1, "parameter value not finite"};
    }
  }
  const ParamSpec& spec = kSpecs[id];
  switch (spec.kind) {
    case ParamKind::kMatrix: {
      gnc::Mat3* m = matrix_field(table, spec.id);
      if (m == nullptr) return ParamLoadResult{RejectReason::kInternal, id, "parameter table"};
      if (n == 3) {
        *m = gnc::Vec3(values[0], values[1], values[2]).asDiagonal();
      } else if (n == 6) {
        *m << values[0], values[3], values[4],  //
            values[3], values[1], values[5],    //
            values[4], values[5], values[2];
      } else {
        return ParamLoadResult{RejectReason::kBadLength, n,
                               "a matrix takes 3 (diagonal) or 6 (symmetric) values"};
      }
      return ParamLoadResult{};
    }
    case ParamKind::kScalar: {
      double* v = scalar_field(table, spec.id);
      if (v == nullptr) return ParamLoadResult{RejectReason::kInternal, id, "parameter table"};
      if (n != 1) return ParamLoadResult{RejectReason::kBadLength, n, "a scalar takes 1 value"};
      *v = values[0];
      return ParamLoadResult{};
    }
    case ParamKind::kFlag: {
      if (n != 1) return ParamLoadResult{RejectReason::kBadLength, n, "a flag takes 1 value"};
      if (values[0] != 0.0 && values[0] != 1.0) {
        return ParamLoadResult{RejectReason::kOutOfRange, 1, "a flag is 0 or 1"};
      }
      table.mode.auto_hold = values[0] == 1.0;  // the only flag
      return ParamLoadResult{};
    }
  }
  return ParamLoadResult{RejectReason::kInternal, id, "parameter table"};
}

int read_param(const gnc::GncParams& table, std::int32_t id, double* values) {
  if (id < 0 || id >= kParamCount) return 0;
  const ParamSpec& spec = kSpecs[id];
  switch (spec.kind) {
    case ParamKind::kMatrix: {
      const gnc::Mat3* m = matrix_field(table, spec.id);
      if (m == nullptr) return 0;
      const double v[6] = {(*m)(0, 0), (*m)(1, 1), (*m)(2, 2), (*m)(0, 1), (*m)(0, 2), (*m)(1, 2)};
      for (int i = 0; i < 6; ++i) values[i] = v[i];
      return 6;
    }
    case ParamKind::kScalar: {
      const double* v = scalar_field(table, spec.id);
      if (v == nullptr) return 0;
      values[0] = *v;
      return 1;
    }
    case ParamKind::kFlag:
      values[0] = table.mode.auto_hold ? 1.0 : 0.0;  // the only flag
      return 1;
  }
  return 0;
}

void ParamTable::reset(const gnc::GncParams& active) {
  inactive_ = active;
  loaded_ = false;
  staged_ = false;
  loads_ = 0;
  loads_at_stage_ = 0;
}

ParamLoadResult ParamTable::load(std::int32_t id, const double* values, int n) {
  scratch_ = inactive_;
  const ParamLoadResult w = write_param(scratch_, id, values, n);
  if (!w.ok()) return w;
  const gnc::ParamCheck c = gnc::validate(scratch_);
  if (!c.ok) return ParamLoadResult{RejectReason::kInvalidTable, id, c.field, c.reason};
  inactive_ = scratch_;
  loaded_ = true;
  ++loads_;
  return ParamLoadResult{};
}

ParamLoadResult ParamTable::load_model(const gnc::Mat3& j_tot, const gnc::Vec3& r,
                                       const gnc::Vec16& k) {
  scratch_ = gnc::with_model(inactive_, j_tot, r, k);
  const gnc::ParamCheck c = gnc::validate(scratch_);
  if (!c.ok) return ParamLoadResult{RejectReason::kInvalidTable, 0, c.field, c.reason};
  inactive_ = scratch_;
  loaded_ = true;
  ++loads_;
  return ParamLoadResult{};
}

bool ParamTable::stage() {
  if (!loaded_) return false;
  staged_table_ = inactive_;
  staged_ = true;
  loads_at_stage_ = loads_;
  return true;
}

void ParamTable::activated(const gnc::GncParams& active) {
  staged_ = false;
  if (loads_ == loads_at_stage_) {
    inactive_ = active;
    loaded_ = false;
  }
}

void ParamTable::discard(const gnc::GncParams& active) {
  inactive_ = active;
  loaded_ = false;
}

}  // namespace rocksteady::fsw
