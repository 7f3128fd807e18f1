#include "ground/dispersion/sampler.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <numeric>

#include "ground/plant/attitude.hpp"

namespace rocksteady::dispersion {

namespace {
constexpr double kPi = 3.14159265358979323846;

bool positive_definite(const Mat3& m) {
  return Eigen::LLT<Mat3>(0.5 * (m + m.transpose())).info() == Eigen::Success;
}
}  // namespace

std::uint64_t splitmix64(std::uint64_t x) {
  // Steele, Lea, Flood (2014).
  std::uint64_t z = x + 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

std::uint64_t mix_seed(std::uint64_t a, std::uint64_t b) {
  return splitmix64(splitmix64(a) ^ (b * 0xD6E8FEB86659FD93ULL + 0x632BE59BD9B4E019ULL));
}

double Rng::normal() {
  return normal_quantile(uniform_open());
}

std::uint64_t Rng::below(std::uint64_t n) {
  if (n <= 1) return 0;
  const std::uint64_t limit = (~std::uint64_t{0}) - ((~std::uint64_t{0}) % n);
  std::uint64_t x = engine_();
  while (x >= limit) x = engine_();
  return x % n;
}

double normal_pdf(double x) {
  if (!std::isfinite(x)) return 0.0;
  return std::exp(-0.5 * x * x) / std::sqrt(2.0 * kPi);
}

double normal_cdf(double x) {
  return 0.5 * std::erfc(-x / std::sqrt(2.0));
}

double normal_quantile(double p) {
  if (p <= 0.0) return -std::numeric_limits<double>::infinity();
  if (p >= 1.0) return std::numeric_limits<double>::infinity();
  // Acklam's rational approximation (|rel. error| < 1.15e-9), then one Halley step on erfc.
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  const double plow = 0.02425;
  double x = 0.0;
  if (p < plow) {
    const double q = std::sqrt(-2.0 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else if (p <= 1.0 - plow) {
    const double q = p - 0.5;
    const double r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  } else {
    const double q = std::sqrt(-2.0 * std::log(1.0 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  }
  const double e = normal_cdf(x) - p;
  const double u = e * std::sqrt(2.0 * kPi) * std::exp(0.5 * x * x);
  return x - u / (1.0 + 0.5 * x * u);
}

Vec3 sphere_direction(double u1, double u2) {
  // Archimedes: z uniform on [-1, 1], longitude uniform.
  const double z = 2.0 * u1 - 1.0;
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = 2.0 * kPi * u2;
  return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}

Eigen::Vector4d random_rotation(double u1, double u2, double u3) {
  // Shoemake (1992): uniform on SO(3).
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const double t1 = 2.0 * kPi * u2, t2 = 2.0 * kPi * u3;
  return Eigen::Vector4d(a * std::sin(t1), a * std::cos(t1), b * std::sin(t2), b * std::cos(t2));
}

Mat3 random_symmetric_direction(Rng& rng) {
  // Gaussian orthogonal ensemble: diagonal N(0, 1), off-diagonal N(0, 1/2); then unit spectral
  // norm.
  Mat3 m;
  for (int i = 0; i < 3; ++i) {
    m(i, i) = rng.normal();
    for (int j = i + 1; j < 3; ++j) {
      m(i, j) = m(j, i) = rng.normal() * std::sqrt(0.5);
    }
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> es(m, Eigen::EigenvaluesOnly);
  const double norm = es.eigenvalues().cwiseAbs().maxCoeff();
  return m / norm;
}

Sampler::Sampler(const DispersionSpec& spec, const config::MissionConfig& mission)
    : spec_(spec), mission_(mission) {
  const auto dims = spec_.dimensions();
  for (const auto& d : dims) bounded_.push_back(d.second->bounded());
  if (spec_.sampling == Sampling::kLatinHypercube) {
    const auto n = static_cast<std::uint32_t>(spec_.draws);
    for (std::size_t k = 0; k < dims.size(); ++k) {
      std::vector<std::uint32_t> perm(n);
      std::iota(perm.begin(), perm.end(), 0U);
      Rng rng(mix_seed(mix_seed(spec_.master_seed, kLhsStream), k));
      for (std::uint32_t i = n; i > 1; --i) {  // Fisher-Yates
        const auto j = static_cast<std::uint32_t>(rng.below(i));
        std::swap(perm[i - 1], perm[j]);
      }
      lhs_perm_.push_back(std::move(perm));
    }
  }
}

std::vector<double> Sampler::coordinates(int index) const {
  const std::uint64_t seed = mix_seed(spec_.master_seed, static_cast<std::uint64_t>(index));
  Rng rng(mix_seed(seed, kScalarStream));
  const std::size_t nd = bounded_.size();
  std::vector<double> u(nd);
  for (std::size_t k = 0; k < nd; ++k) u[k] = rng.uniform();  // always drawn: same stream use
  switch (spec_.sampling) {
    case Sampling::kRandom:
      break;
    case Sampling::kLatinHypercube: {
      if (nd == 0) break;
      const double n = static_cast<double>(spec_.draws);
      const auto i = static_cast<std::size_t>(index) % lhs_perm_.front().size();
      for (std::size_t k = 0; k < nd; ++k) u[k] = (lhs_perm_[k][i] + u[k]) / n;
      break;
    }
    case Sampling::kCorners: {
      // The 2^b corners of the bounded dimensions first (bit k of the index: low or high bound of
      // the k-th bounded dimension), then points on the faces: one bounded dimension, chosen by the
      // draw, at one of its bounds, the others uniform. Unbounded dimensions stay random.
      std::vector<std::size_t> b;
      for (std::size_t k = 0; k < nd; ++k) {
        if (bounded_[k]) b.push_back(k);
      }
      const std::uint64_t corners =
          b.size() >= 40 ? ~std::uint64_t{0} : (std::uint64_t{1} << b.size());
      const auto i = static_cast<std::uint64_t>(index);
      if (i < corners) {
        for (std::size_t j = 0; j < b.size(); ++j) u[b[j]] = ((i >> j) & 1U) != 0 ? 1.0 : 0.0;
      } else if (!b.empty()) {
        const std::uint64_t pick = rng.below(2 * b.size());
        u[b[pick / 2]] = (pick % 2) != 0 ? 1.0 : 0.0;
      }
      break;
    }
  }
  return u;
}

DrawParams Sampler::draw(int index) const {
  DrawParams d;
  d.index = index;
  d.seed = mix_seed(spec_.master_seed, static_cast<std::uint64_t>(index));
  d.u = coordinates(index);
  // Scalars: through their quantile functions at the draw's coordinates.
  const auto dims = spec_.dimensions();
  auto value = [&](const Scalar& s) {
    for (std::size_t k = 0; k < dims.size(); ++k) {
      if (dims[k].second == &s) return s.quantile(d.u[k]);
    }
    return s.value;  // fixed
  };
  d.delta_j_norm = value(spec_.delta_j_norm);
  d.delta_r_norm = value(spec_.delta_r_norm);
  d.initial_rate_norm = value(spec_.initial_rate_norm);
  d.gyro_psd = value(spec_.gyro_psd);
  d.star_psd = value(spec_.star_psd);
  d.disturbance_sigma_nm = value(spec_.disturbance_sigma_nm);
  d.u_max_n = value(spec_.u_max_n);

  Rng dir(mix_seed(d.seed, kDirectionStream));
  // dJ: J_ast - dJ must stay positive definite; random directions are redrawn until it is.
  const Mat3& j_ast = mission_.mass.j_ast;
  if (spec_.delta_j_direction == DirectionKind::kMission) {
    d.delta_j = d.delta_j_norm * Mat3(mission_.delta_j_diag_direction.asDiagonal());
    if (!positive_definite(j_ast - d.delta_j)) {
      d.error = "J_ast - dJ is not positive definite along the mission's direction";
    }
  } else {
    Rng mat(mix_seed(d.seed, kMatrixStream));
    for (;;) {
      d.delta_j = d.delta_j_norm * random_symmetric_direction(mat);
      if (positive_definite(j_ast - d.delta_j)) break;
      if (d.pd_redraws >= spec_.max_pd_redraws) {
        d.error = "no positive-definite J_ast - dJ within " + std::to_string(spec_.max_pd_redraws) +
                  " redraws of the direction";
        break;
      }
      ++d.pd_redraws;
    }
  }
  // Directions (always drawn, so each draw uses its stream the same way whatever the file says).
  const double r1 = dir.uniform(), r2 = dir.uniform();
  const double w1 = dir.uniform(), w2 = dir.uniform();
  const double a1 = dir.uniform(), a2 = dir.uniform(), a3 = dir.uniform();
  const Vec3 r_dir = spec_.delta_r_direction == DirectionKind::kSphere ? sphere_direction(r1, r2)
                                                                       : mission_.delta_r_direction;
  d.delta_r = d.delta_r_norm * r_dir;
  Vec3 w_dir = mission_.initial_omega;
  if (spec_.initial_rate_direction == DirectionKind::kSphere) {
    w_dir = sphere_direction(w1, w2);
  } else if (w_dir.norm() > 0.0) {
    w_dir.normalize();
  }
  d.omega0 = d.initial_rate_norm * w_dir;
  if (spec_.initial_attitude == DirectionKind::kRandomRotation) {
    d.mrp0 = plant::att::quat_to_mrp(random_rotation(a1, a2, a3));
  } else {
    d.mrp0 = mission_.initial_mrp;
  }
  d.noise_seed = spec_.noise_seed_per_draw ? mix_seed(d.seed, kNoiseSeedStream) : spec_.noise_seed;
  // Truth beyond the study, from its own stream (files without these keys draw nothing).
  Rng extra(mix_seed(d.seed, kTruthExtrasStream));
  const double k_sigma = value(spec_.thruster_strength_sigma);
  for (int i = 0; i < gnc::kThrusters; ++i) {
    const double e = std::max(-3.0, std::min(3.0, extra.normal()));
    d.thruster_strength(i) = 1.0 + k_sigma * e;
  }
  const double b1 = extra.uniform(), b2 = extra.uniform();
  d.gyro_bias = value(spec_.gyro_bias_norm_rad_s) * sphere_direction(b1, b2);

  // Fault dispersion: thruster x kind x onset x case, on a grid or at random.
  const FaultPlan& fp = spec_.faults;
  if (fp.enabled) {
    const std::size_t nt = fp.thrusters.size(), nk = fp.kinds.size(), no = fp.onsets_s.size();
    const std::size_t nc = fp.case_files.empty() ? 1 : fp.case_files.size();
    std::size_t it = 0, ik = 0, io = 0, ic = 0;
    if (fp.grid) {
      std::size_t i = static_cast<std::size_t>(index) % fp.grid_size();
      it = i % nt;
      i /= nt;
      ik = i % nk;
      i /= nk;
      io = i % no;
      ic = i / no;
    } else {
      Rng f(mix_seed(d.seed, kFaultStream));
      it = static_cast<std::size_t>(f.below(nt));
      ik = static_cast<std::size_t>(f.below(nk));
      io = static_cast<std::size_t>(f.below(no));
      ic = static_cast<std::size_t>(f.below(nc));
    }
    d.has_fault = true;
    d.fault.thruster = fp.thrusters[it];
    d.fault.kind = fp.kinds[ik];
    d.fault.onset_s = fp.onsets_s[io];
    d.fault.factor = d.fault.kind == plant::FaultKind::kDegraded ? fp.degraded_factor : 1.0;
    if (!fp.case_files.empty()) {
      d.case_file = fp.case_files[ic];
      d.case_number = fp.case_numbers[ic];
    }
  }
  return d;
}

}  // namespace rocksteady::dispersion
