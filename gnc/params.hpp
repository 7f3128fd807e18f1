// Plain-data parameters of the flight core, and their validation (returns the first bad field).
// Each module owns its configuration struct in its own header (the mode manager ModeParams, the state
// filter EstimatorParams, the references GuidanceParams, the control laws their gains, the
// allocator AllocatorKind); GncParams aggregates them with the model (mass properties, RCS layout).
// Defaults are the study's Table 4 (SPEC §5) where the study gives them; [Rocksteady choice] marks
// the rest.
#pragma once

#include "gnc/allocation/allocator.hpp"
#include "gnc/check.hpp"
#include "gnc/control/laws.hpp"
#include "gnc/estimation/identifier.hpp"
#include "gnc/estimation/mekf.hpp"
#include "gnc/estimation/state_filter.hpp"
#include "gnc/fdi/fault_detector.hpp"
#include "gnc/guidance/references.hpp"
#include "gnc/io.hpp"
#include "gnc/mode/mode_manager.hpp"
#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {

struct GncParams {
  double dt{0.1};  // GNC period, s (10 Hz)
  MassProperties mass_hat{};  // the flight software's estimate (hatted quantities, Eq. 6)
  RcsLayout rcs{};
  LawId law{LawId::kNtcl};
  TrackingGains ntcl{};
  TrackingGains el{};
  TrackingGains feedforward{};
  IntegralGains integral{};
  AdaptiveGains adaptive{};
  So3Gains so3{};
  DpdGains dpd{};
  GuidanceParams guidance{};
  EstimatorParams estimator{};
  // estimator.kind == kMekf: the MEKF's noise model and gate. Its dt, gyro_max_rate and
  // quat_norm_tolerance are the table's dt and estimator fields (build_mekf_config).
  MekfConfig mekf{};
  IdentificationParams identification{};  // on-line identification of J_tot, r_SO/BCM, k_i
  FaultDetectorParams fdi{};               // thruster fault detection and isolation (gnc/fdi)
  // Relative 1 sigma of the table's J_tot when the detector runs without identification (the
  // asteroid known to ~10 %): the detector's model-uncertainty term, so it stays quiet.
  double fdi_table_rel_sigma{0.1};
  ModeParams mode{};
  // SPEC §4: the study's pseudoinverse, Eq. (53), or the fuel-optimal allocation, Eq. (52).
  AllocatorKind allocator{AllocatorKind::kPseudoInverse};
  double isp_s{287.0};  // Eq. (54)
  double g0{9.8};
};

// The study's parameters (Tables 2 and 4) with the estimated mass properties equal to the true ones.
GncParams study_gnc_params(double u_max);

// The identifier's flight settings, as configs/gnc.yaml's identification section gives them for a
// gyro of per-sample noise gyro_sigma (rad/s): the noisy sensors' window when gyro_sigma > 0, the
// data sheet's gyro bias only then. Enabling and adoption are left as they are. The bare-metal
// firmware has no YAML reader and flies these; tests/config holds them equal to what the
// configuration loader reads from gnc.yaml.
void apply_flight_identification_settings(GncParams& p, double gyro_sigma);

// The gains of every law, as ControlLaws takes them.
LawGains law_gains(const GncParams& p);

// The MEKF's and the identifier's configuration as the table defines them: tuning from
// p.mekf / p.identification.config, tick, sample checks, geometry and priors from the table.
MekfConfig build_mekf_config(const GncParams& p);
IdentifierConfig build_identifier_config(const GncParams& p);

// The model the table flies with a different J_tot, r_SO/BCM and thruster strengths: r_SO/BCM := r,
// J_ast := J_tot - (the spacecraft's part of Eq. (1) at the given r), strength := k. The result is
// validated by the caller (validate() refuses a J_ast that is not positive definite).
GncParams with_model(const GncParams& p, const Mat3& j_tot, const Vec3& r, const Vec16& k);

using ParamCheck = Check;

// Validates every field; returns the first bad one with a reason (non-positive-definite inertia or
// gains, rank-deficient B_hat, non-finite values, bad rates or thresholds).
ParamCheck validate(const GncParams& p);

// Helpers shared by validation and the components.
bool all_finite(const Mat3& m);
bool is_symmetric_positive_definite(const Mat3& m);

}  // namespace rocksteady::gnc
