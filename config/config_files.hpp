// Rocksteady's configuration files (configs/): mission.yaml, gnc.yaml and the case files, loaded
// strictly (unknown or missing keys, wrong shapes, non-positive-definite inertias, negative noise
// powers and unreadable files are a ConfigError naming the file, the key and the reason), and the
// flight core's GncParams (estimated quantities, SPEC Eq. 6) built from them. Flight side: used by
// rocksteady-fsw at start-up (never in a tick); ground/config adds the plant's truth.
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include <yaml-cpp/yaml.h>

#include "gnc/params.hpp"
#include "config/config_error.hpp"

namespace rocksteady::config {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

struct MissionConfig {
  std::string file;
  gnc::MassProperties mass{};                 // true
  std::array<double, 4> pod_azimuths_deg{};  // SPEC §4
  double pod_radius_m{2.5};
  double pod_plane_z_m{3.0};
  double isp_s{287.0};
  double g0{9.8};
  double sensor_period_s{0.1};
  double disturbance_sigma_nm{0.0};
  double disturbance_hold_s{10.0};
  Vec3 initial_mrp{Vec3::Zero()};
  Vec3 initial_omega{Vec3::Zero()};
  Vec3 delta_j_diag_direction{-1.0, 1.0, 0.5};  // scaled to unit spectral norm on load
  Vec3 delta_r_direction{Vec3::Ones()};         // unit length on load
  double omega_tol_rad_s{1e-4};
  double q_tol{1e-2};
  int rk4_substeps{1};
};

enum class EstimatorChoice { kAuto, kPassThrough, kFilter, kMekf };

struct GncConfig {
  std::string file;
  gnc::GncParams params{};  // mass_hat, rcs and law are filled in by assemble()
  EstimatorChoice estimator{EstimatorChoice::kAuto};
  // Identification window when the case's sensors are noisy (params.identification.config.window_s
  // is the quiet-sensor one): a longer window averages the gyro noise down (estimation README §I.4).
  double id_window_noisy_s{60.0};
  // Fault-detector residual window when the case's sensors are noisy (params.fdi.window_ticks is
  // the quiet-sensor one).
  int fdi_window_noisy_ticks{25};
  // (F30) With noisy sensors the detector's window is the shortest of window_ticks ..
  // window_noisy_ticks in which the weakest jet's stuck-on signature stands this many sigma of the
  // case's gyro noise above it (0: window_noisy_ticks whenever the sensors are noisy).
  double fdi_window_snr{0.0};
};

struct CaseConfig {
  std::string file;
  int number{0};
  std::string description;
  double delta_j_norm{0.0};   // ||dJ_ast||_2, kg m^2
  double delta_r_norm{0.0};   // ||dr_SO/BCM||_2, m
  double gyro_psd{0.0};       // P(dw)
  double star_psd{0.0};       // P(dq)
  double u_max{200.0};        // N
  Vec3 bias_nm{Vec3::Zero()};
  double duration_s{1e5};
  std::uint64_t seed{1};
  // Optional `plant_truth:` mapping (gyro bias, thruster strengths beyond the study's truth),
  // applied by the ground's assemble() (ground/config); null when absent.
  YAML::Node plant_truth{};
};

MissionConfig load_mission(const std::string& path);
GncConfig load_gnc(const std::string& path);
CaseConfig load_case(const std::string& path);
// Applies the case's errors (true minus estimate) and validates the result.
// The flight software's parameters, Eq. (6): the estimates (true minus the case's errors), the
// mission's RCS layout at the case's u_max, the gains of gnc.yaml, the estimator choice; validated.
gnc::GncParams flight_params(const MissionConfig& mission, const GncConfig& gnc, const CaseConfig& c);
// (F30) The detector's window for a gyro of per-sample noise gyro_sigma: the shortest n in
// [min_ticks, max_ticks] whose least-squares slope of the weakest jet's stuck-on ramp (the smallest
// |J^-1 B_c| u_max of the table's model) stands snr sigma above the gyro's noise:
// a dt sqrt(n (n^2 - 1) / 12) / (c sigma) >= snr, c = 1 with the centred noise (F28), sqrt(2)
// without. max_ticks when none does; min_ticks for a noise-free gyro.
int fdi_window_for_noise(const gnc::GncParams& p, double gyro_sigma, double snr, int min_ticks,
                         int max_ticks);

gnc::GncParams load_flight_params(const std::string& mission_path, const std::string& gnc_path,
                                  const std::string& case_path);

// The RCS layout of SPEC §4 with the mission's pod azimuths, radius and plane.
gnc::RcsLayout rcs_layout(const MissionConfig& m, double u_max);

}  // namespace rocksteady::config
