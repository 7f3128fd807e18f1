// Draws: each draw is a pure function of (master seed, draw index, the dispersion file). Random
// numbers come from counter-based seeds: draw seed = splitmix64(master seed, index), and each use
// (scalars, directions, matrix redraws, noise seed) has its own stream seeded from it, so a draw
// never depends on which other draws ran, in which order, or where.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "config/config_files.hpp"
#include "ground/dispersion/spec.hpp"

namespace rocksteady::dispersion {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

std::uint64_t splitmix64(std::uint64_t x);
// The seed of one stream of one draw.
std::uint64_t mix_seed(std::uint64_t a, std::uint64_t b);

// Uniform doubles from a 64-bit engine: (x >> 11) * 2^-53, in [0, 1). Same bits on every platform.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double uniform_open() {  // (0, 1)
    double u = 0.0;
    while (u == 0.0) u = uniform();
    return u;
  }
  double normal();                       // standard normal by the quantile of uniform_open()
  std::uint64_t below(std::uint64_t n);  // uniform integer in [0, n), unbiased
  std::uint64_t bits() { return engine_(); }

 private:
  std::mt19937_64 engine_;
};

double normal_pdf(double x);
double normal_cdf(double x);
double normal_quantile(double p);  // inverse of normal_cdf on (0, 1), ~1e-15 relative

// Directions from uniforms (the tests check their distributions).
Vec3 sphere_direction(double u1, double u2);                       // uniform on S^2
Eigen::Vector4d random_rotation(double u1, double u2, double u3);  // uniform unit quaternion [v; s]
Mat3 random_symmetric_direction(Rng& rng);                         // GOE, unit spectral norm

// One draw's parameters, as sampled.
struct DrawParams {
  int index{0};
  std::uint64_t seed{0};  // the draw's seed (from the master seed and the index)
  std::vector<double> u;  // the hypercube coordinates of the spec's dimensions
  double delta_j_norm{0.0};
  Mat3 delta_j{Mat3::Zero()};  // true minus estimate
  int pd_redraws{0};           // dJ directions rejected because J_ast - dJ was not PD
  double delta_r_norm{0.0};
  Vec3 delta_r{Vec3::Zero()};
  double initial_rate_norm{0.0};
  Vec3 omega0{Vec3::Zero()};
  Vec3 mrp0{Vec3::Zero()};  // shadow-normalised
  double gyro_psd{0.0};
  double star_psd{0.0};
  double disturbance_sigma_nm{0.0};
  std::uint64_t noise_seed{1};
  double u_max_n{200.0};
  gnc::Vec16 thruster_strength{gnc::Vec16::Ones()};  // true strength factors
  Vec3 gyro_bias{Vec3::Zero()};                      // true constant gyro bias, rad/s
  // Fault dispersion: the case file flown (empty: the parameters above) and the thruster fault.
  std::string case_file;
  int case_number{0};
  bool has_fault{false};
  plant::ThrusterFault fault{};
  std::string error;  // non-empty: no valid draw (e.g. no PD estimate within the limit)
};

class Sampler {
 public:
  // The mission supplies J_ast (for the PD test), the fixed directions and the initial state.
  Sampler(const DispersionSpec& spec, const config::MissionConfig& mission);
  DrawParams draw(int index) const;
  // The hypercube coordinates of draw `index` (exposed for the tests).
  std::vector<double> coordinates(int index) const;

 private:
  DispersionSpec spec_;
  config::MissionConfig mission_;
  std::vector<std::vector<std::uint32_t>> lhs_perm_;  // per dimension (Latin hypercube)
  std::vector<bool> bounded_;
};

// Sampler streams (stable ids: changing them changes every draw).
enum Stream : std::uint64_t {
  kScalarStream = 1,
  kDirectionStream = 2,
  kMatrixStream = 3,
  kNoiseSeedStream = 4,
  kLhsStream = 5,
  kFaultStream = 6,
  kTruthExtrasStream = 7,  // thruster strengths, gyro bias
};

}  // namespace rocksteady::dispersion
