// A dispersion file (configs/dispersions/*.yaml): the distributions of the uncertain quantities,
// the strategies to fly, the number of draws, the master seed and the sampling plan. Loaded
// strictly (unknown or missing keys, bad shapes, empty ranges are a ConfigError naming file, key
// and reason).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ground/campaign/runner.hpp"
#include "ground/campaign/strategy.hpp"
#include "ground/plant/plant.hpp"

namespace rocksteady::dispersion {

// A scalar distribution. Every kind is sampled through its quantile function of one uniform
// u in [0, 1], so Latin-hypercube and corner sampling apply to all of them alike.
struct Scalar {
  enum class Kind { kFixed, kUniform, kLogUniform, kNormal };
  Kind kind{Kind::kFixed};
  double value{0.0};  // fixed
  double min{0.0};    // uniform, log-uniform; normal: truncation (may be +-inf)
  double max{0.0};
  double mean{0.0};   // normal
  double sigma{0.0};  // normal
  // A bounded dimension of the sampling hypercube (fixed values are not a dimension; a normal is
  // bounded only when truncated on both sides).
  bool is_dimension() const;
  bool bounded() const;
  // The value at probability u in [0, 1] (u = 0 and 1 give the bounds of bounded distributions).
  double quantile(double u) const;
  // Closed forms for the tests and the report.
  double mean_value() const;
  double variance() const;
  std::string describe() const;
};

// How a direction (unit vector, rotation or matrix direction) is chosen.
enum class DirectionKind {
  kMission,          // the mission file's fixed direction (SPEC §5 "Error directions")
  kSphere,           // uniform on the unit sphere (vectors)
  kRandomSymmetric,  // dJ: a random symmetric matrix (GOE) scaled to unit spectral norm
  kRandomRotation,   // initial attitude: uniform on SO(3)
};
const char* to_string(DirectionKind k);

enum class Sampling { kRandom, kLatinHypercube, kCorners };
const char* to_string(Sampling s);

// A fault dispersion (optional `faults:` key): one thruster fault per draw, over thruster x kind x
// onset x (optionally) study case.
//   faults:
//     thrusters: all                 # or a list of physical thrusters 0..15 (4 pod + position)
//     kinds: [stuck_off, stuck_on, degraded]
//     degraded_factor: 0.5           # thrust factor of the degraded kind, in (0, 1)
//     onsets_s: [60, 20000, 60000]   # plant time of the onset
//     cases: [1, 2, 3, 4, 5, 6, 7]   # optional: fly these case files (numbers: <dir>/../cases/caseN.yaml
//                                    # next to the dispersion file; strings: paths relative to it);
//                                    # each draw then flies its case as `campaign` does, and the
//                                    # `parameters` section must be absent
//     plan: grid                     # grid: draw i is combination i mod the grid size (thruster
//                                    # fastest, then kind, onset, case); random: each draw picks each
//                                    # factor uniformly from its own stream
struct FaultPlan {
  bool enabled{false};
  bool grid{true};
  std::vector<int> thrusters;
  std::vector<plant::FaultKind> kinds;
  double degraded_factor{0.5};
  std::vector<double> onsets_s;
  std::vector<std::string> case_files;  // empty: the `parameters` draws
  std::vector<int> case_numbers;        // the case files' `case` numbers
  std::size_t grid_size() const {
    return thrusters.size() * kinds.size() * onsets_s.size() *
           (case_files.empty() ? 1 : case_files.size());
  }
};

struct DispersionSpec {
  std::string file;
  std::string name;
  std::string description;
  int draws{1};
  std::uint64_t master_seed{1};
  Sampling sampling{Sampling::kRandom};
  double duration_s{1e5};
  std::vector<campaign::Strategy> strategies;
  // The replan strategies' policy and planning latency (optional map `replan`).
  campaign::ReplanOptions replan;
  // The flight allocator for every run (optional key; default: the GNC file's).
  bool override_allocator{false};
  gnc::AllocatorKind allocator{gnc::AllocatorKind::kPseudoInverse};

  Scalar delta_j_norm;  // ||dJ_ast||_2, kg m^2 (true minus estimate)
  DirectionKind delta_j_direction{DirectionKind::kMission};
  int max_pd_redraws{1000};  // dJ directions redrawn until J_ast - dJ is positive definite
  Scalar delta_r_norm;       // ||dr_SO/BCM||, m
  DirectionKind delta_r_direction{DirectionKind::kMission};
  Scalar initial_rate_norm;  // |omega_0|, rad/s
  DirectionKind initial_rate_direction{DirectionKind::kMission};
  DirectionKind initial_attitude{DirectionKind::kMission};  // mission or random_rotation
  Scalar gyro_psd;                                          // P(dw)
  Scalar star_psd;                                          // P(dq)
  Scalar disturbance_sigma_nm;                              // per axis
  bool noise_seed_per_draw{true};                           // else noise_seed
  std::uint64_t noise_seed{1};
  Scalar u_max_n;
  // Optional truth beyond the study (absent: none). Per-thruster strength factors k_i = 1 + e_i,
  // e_i normal with this sigma, truncated to +-3 sigma, drawn independently per thruster; a
  // constant gyro bias of this norm in a uniformly random direction.
  Scalar thruster_strength_sigma;
  Scalar gyro_bias_norm_rad_s;
  FaultPlan faults{};

  // The bounded scalars in a fixed order (the hypercube's dimensions), with their key names.
  std::vector<std::pair<std::string, const Scalar*>> dimensions() const;
};

DispersionSpec load_spec(const std::string& path);

}  // namespace rocksteady::dispersion
