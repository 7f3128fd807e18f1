#include "ground/dispersion/spec.hpp"

#include <cmath>
#include <filesystem>
#include <cstdio>
#include <limits>

#include "config/yaml_reader.hpp"
#include "ground/dispersion/sampler.hpp"

namespace rocksteady::dispersion {

using config::ConfigError;
using config::MapReader;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string fmt_g(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// A distribution: a plain number (fixed), or a mapping with `distribution:` fixed | uniform |
// log_uniform | normal and its parameters.
Scalar scalar(MapReader& parent, const std::string& key, bool allow_negative) {
  Scalar s;
  const YAML::Node n = parent.get(key);
  auto check_sign = [&](double v, const std::string& k) {
    if (!allow_negative && v < 0.0) parent.fail(k, "must not be negative");
  };
  if (n.IsScalar()) {
    s.kind = Scalar::Kind::kFixed;
    s.value = parent.number(key);
    check_sign(s.value, key);
    return s;
  }
  if (!n.IsMap()) {
    parent.fail(key, "expected a number or a mapping with 'distribution'");
  }
  MapReader r = parent.map(key);
  const std::string kind = r.text("distribution");
  if (kind == "fixed") {
    s.kind = Scalar::Kind::kFixed;
    s.value = r.number("value");
    check_sign(s.value, key + ".value");
  } else if (kind == "uniform" || kind == "log_uniform") {
    s.kind = kind == "uniform" ? Scalar::Kind::kUniform : Scalar::Kind::kLogUniform;
    s.min = r.number("min");
    s.max = r.number("max");
    check_sign(s.min, key + ".min");
    if (!(s.max > s.min)) r.fail("max", "must be greater than min");
    if (s.kind == Scalar::Kind::kLogUniform && !(s.min > 0.0)) {
      r.fail("min", "a log-uniform distribution needs min > 0");
    }
  } else if (kind == "normal") {
    s.kind = Scalar::Kind::kNormal;
    s.mean = r.number("mean");
    s.sigma = r.positive("sigma");
    s.min = r.has("min") ? r.number("min") : -kInf;
    s.max = r.has("max") ? r.number("max") : kInf;
    if (!allow_negative && !(s.min >= 0.0)) {
      r.fail("min", "this quantity is not negative: the normal must be truncated at min >= 0");
    }
    if (!(s.max > s.min)) r.fail("max", "must be greater than min");
    // The truncation must keep some probability (within 30 sigma of the mean).
    if (s.max < s.mean - 30.0 * s.sigma || s.min > s.mean + 30.0 * s.sigma) {
      r.fail("mean", "the truncation interval [min, max] is more than 30 sigma from the mean");
    }
  } else {
    r.fail("distribution", "expected fixed, uniform, log_uniform or normal, got '" + kind + "'");
  }
  r.finish();
  return s;
}

DirectionKind direction(MapReader& r, const std::string& key, bool vector, bool matrix,
                        bool rotation) {
  const std::string v = r.text(key);
  if (v == "mission") return DirectionKind::kMission;
  if (vector && v == "sphere") return DirectionKind::kSphere;
  if (matrix && v == "random_symmetric") return DirectionKind::kRandomSymmetric;
  if (rotation && v == "random_rotation") return DirectionKind::kRandomRotation;
  std::string allowed = "mission";
  if (vector) allowed += " or sphere";
  if (matrix) allowed += " or random_symmetric";
  if (rotation) allowed += " or random_rotation";
  r.fail(key, "expected " + allowed + ", got '" + v + "'");
}

}  // namespace

bool Scalar::is_dimension() const {
  return kind != Kind::kFixed;
}

bool Scalar::bounded() const {
  return kind == Kind::kUniform || kind == Kind::kLogUniform ||
         (kind == Kind::kNormal && std::isfinite(min) && std::isfinite(max));
}

double Scalar::quantile(double u) const {
  switch (kind) {
    case Kind::kFixed:
      return value;
    case Kind::kUniform:
      return u <= 0.0 ? min : (u >= 1.0 ? max : min + u * (max - min));
    case Kind::kLogUniform:
      return u <= 0.0 ? min : (u >= 1.0 ? max : std::exp(std::log(min) + u * std::log(max / min)));
    case Kind::kNormal: {
      if (u <= 0.0 && std::isfinite(min)) return min;
      if (u >= 1.0 && std::isfinite(max)) return max;
      const double a = normal_cdf((min - mean) / sigma);
      const double b = normal_cdf((max - mean) / sigma);
      const double p = a + u * (b - a);
      const double x = mean + sigma * normal_quantile(p);
      return std::min(max, std::max(min, x));
    }
  }
  return value;
}

double Scalar::mean_value() const {
  switch (kind) {
    case Kind::kFixed:
      return value;
    case Kind::kUniform:
      return 0.5 * (min + max);
    case Kind::kLogUniform:
      return (max - min) / std::log(max / min);
    case Kind::kNormal: {
      const double a = (min - mean) / sigma, b = (max - mean) / sigma;
      const double z = normal_cdf(b) - normal_cdf(a);
      return mean + sigma * (normal_pdf(a) - normal_pdf(b)) / z;
    }
  }
  return value;
}

double Scalar::variance() const {
  switch (kind) {
    case Kind::kFixed:
      return 0.0;
    case Kind::kUniform:
      return (max - min) * (max - min) / 12.0;
    case Kind::kLogUniform: {
      const double l = std::log(max / min);
      const double m = (max - min) / l;
      return (max * max - min * min) / (2.0 * l) - m * m;
    }
    case Kind::kNormal: {
      const double a = (min - mean) / sigma, b = (max - mean) / sigma;
      const double z = normal_cdf(b) - normal_cdf(a);
      const double pa = normal_pdf(a), pb = normal_pdf(b);
      const double ta = std::isfinite(a) ? a * pa : 0.0;
      const double tb = std::isfinite(b) ? b * pb : 0.0;
      const double r = (pa - pb) / z;
      return sigma * sigma * (1.0 + (ta - tb) / z - r * r);
    }
  }
  return 0.0;
}

std::string Scalar::describe() const {
  switch (kind) {
    case Kind::kFixed:
      return fmt_g(value);
    case Kind::kUniform:
      return "uniform [" + fmt_g(min) + ", " + fmt_g(max) + "]";
    case Kind::kLogUniform:
      return "log-uniform [" + fmt_g(min) + ", " + fmt_g(max) + "]";
    case Kind::kNormal:
      return "normal(" + fmt_g(mean) + ", " + fmt_g(sigma) + ") on [" + fmt_g(min) + ", " +
             fmt_g(max) + "]";
  }
  return "?";
}

const char* to_string(DirectionKind k) {
  switch (k) {
    case DirectionKind::kMission:
      return "mission";
    case DirectionKind::kSphere:
      return "sphere";
    case DirectionKind::kRandomSymmetric:
      return "random_symmetric";
    case DirectionKind::kRandomRotation:
      return "random_rotation";
  }
  return "?";
}

const char* to_string(Sampling s) {
  switch (s) {
    case Sampling::kRandom:
      return "random";
    case Sampling::kLatinHypercube:
      return "latin_hypercube";
    case Sampling::kCorners:
      return "corners";
  }
  return "?";
}

std::vector<std::pair<std::string, const Scalar*>> DispersionSpec::dimensions() const {
  const std::pair<std::string, const Scalar*> all[] = {
      {"delta_j_ast_norm_kg_m2", &delta_j_norm},
      {"delta_r_so_bcm_norm_m", &delta_r_norm},
      {"initial_rate_norm_rad_s", &initial_rate_norm},
      {"gyro_noise_psd_rad2_s2", &gyro_psd},
      {"star_noise_psd", &star_psd},
      {"disturbance_sigma_nm", &disturbance_sigma_nm},
      {"u_max_n", &u_max_n},
      {"thruster_strength_sigma", &thruster_strength_sigma},
      {"gyro_bias_norm_rad_s", &gyro_bias_norm_rad_s},
  };
  std::vector<std::pair<std::string, const Scalar*>> out;
  for (const auto& d : all) {
    if (d.second->is_dimension()) out.push_back(d);
  }
  return out;
}

namespace {

void load_faults(MapReader r, const std::string& path, FaultPlan& f) {
  f.enabled = true;
  const YAML::Node th = r.get("thrusters");
  if (th.IsScalar() && th.as<std::string>() == "all") {
    for (int i = 0; i < hal::kThrusters; ++i) f.thrusters.push_back(i);
  } else if (th.IsSequence() && th.size() > 0) {
    for (std::size_t i = 0; i < th.size(); ++i) {
      int t = -1;
      try {
        t = th[i].as<int>();
      } catch (const YAML::Exception&) {
        r.fail("thrusters", "expected 'all' or a list of thrusters 0..15");
      }
      if (t < 0 || t >= hal::kThrusters) {
        r.fail("thrusters", "thruster " + std::to_string(t) + " is not in [0, 15]");
      }
      f.thrusters.push_back(t);
    }
  } else {
    r.fail("thrusters", "expected 'all' or a non-empty list of thrusters 0..15");
  }
  const YAML::Node kinds = r.get("kinds");
  if (!kinds.IsSequence() || kinds.size() == 0) {
    r.fail("kinds", "expected a non-empty list of stuck_off, stuck_on, degraded");
  }
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    plant::FaultKind k = plant::FaultKind::kNone;
    const std::string name = kinds[i].IsScalar() ? kinds[i].as<std::string>() : "";
    if (!plant::parse_fault_kind(name, k)) {
      r.fail("kinds", "expected stuck_off, stuck_on or degraded, got '" + name + "'");
    }
    f.kinds.push_back(k);
  }
  if (r.has("degraded_factor")) {
    f.degraded_factor = r.number("degraded_factor");
    if (!(f.degraded_factor > 0.0 && f.degraded_factor < 1.0)) {
      r.fail("degraded_factor", "must be in (0, 1)");
    }
  }
  const YAML::Node on = r.get("onsets_s");
  if (!on.IsSequence() || on.size() == 0) r.fail("onsets_s", "expected a non-empty list of times");
  for (std::size_t i = 0; i < on.size(); ++i) {
    double t = -1.0;
    try {
      t = on[i].as<double>();
    } catch (const YAML::Exception&) {
      r.fail("onsets_s", "expected numbers");
    }
    if (!std::isfinite(t) || t < 0.0) r.fail("onsets_s", "every onset must be finite and >= 0");
    f.onsets_s.push_back(t);
  }
  if (r.has("cases")) {
    const YAML::Node cs = r.get("cases");
    if (!cs.IsSequence() || cs.size() == 0) r.fail("cases", "expected a non-empty list of cases");
    const std::filesystem::path dir = std::filesystem::path(path).parent_path();
    for (std::size_t i = 0; i < cs.size(); ++i) {
      const std::string v = cs[i].IsScalar() ? cs[i].Scalar() : "";
      std::string file;
      if (!v.empty() && v.find_first_not_of("0123456789") == std::string::npos) {
        file = (dir / ".." / "cases" / ("case" + v + ".yaml")).lexically_normal().string();
      } else if (!v.empty()) {
        file = (dir / v).lexically_normal().string();
      } else {
        r.fail("cases", "expected case numbers or case-file paths");
      }
      try {
        f.case_numbers.push_back(config::load_case(file).number);
      } catch (const config::ConfigError& e) {
        r.fail("cases", std::string("case '") + v + "': " + e.what());
      }
      f.case_files.push_back(file);
    }
  }
  if (r.has("plan")) {
    const std::string plan = r.text("plan");
    if (plan == "grid") {
      f.grid = true;
    } else if (plan == "random") {
      f.grid = false;
    } else {
      r.fail("plan", "expected grid or random, got '" + plan + "'");
    }
  }
  r.finish();
}

}  // namespace

DispersionSpec load_spec(const std::string& path) {
  DispersionSpec s;
  s.file = path;
  MapReader doc(config::load_yaml_file(path), path, "");
  s.name = doc.text("name");
  if (s.name.empty() || s.name.find_first_of("/ \t") != std::string::npos) {
    doc.fail("name", "must be a non-empty word without spaces or '/'");
  }
  s.description = doc.has("description") ? doc.text("description") : std::string();
  s.draws = doc.integer("draws");
  if (s.draws < 1 || s.draws > 10000000) doc.fail("draws", "must be in [1, 10000000]");
  s.master_seed = doc.unsigned_integer("master_seed");
  const std::string sampling = doc.text("sampling");
  if (sampling == "random") {
    s.sampling = Sampling::kRandom;
  } else if (sampling == "latin_hypercube") {
    s.sampling = Sampling::kLatinHypercube;
  } else if (sampling == "corners") {
    s.sampling = Sampling::kCorners;
  } else {
    doc.fail("sampling", "expected random, latin_hypercube or corners, got '" + sampling + "'");
  }
  s.duration_s = doc.positive("duration_s");

  const YAML::Node strategies = doc.get("strategies");
  if (!strategies.IsSequence() || strategies.size() == 0) {
    doc.fail("strategies", "expected a non-empty list of strategy names");
  }
  for (std::size_t i = 0; i < strategies.size(); ++i) {
    const std::string name = strategies[i].IsScalar() ? strategies[i].as<std::string>() : "";
    const auto st = campaign::parse_strategy(name);
    if (!st) {
      doc.fail("strategies",
               "unknown strategy '" + name + "' (e.g. ntcl+fuel_optimal, adaptive+dpd_ref, dpd)");
    }
    for (const campaign::Strategy& prev : s.strategies) {
      if (prev.name == st->name) doc.fail("strategies", "'" + name + "' is listed twice");
    }
    s.strategies.push_back(*st);
  }

  if (doc.has("allocator")) {
    const std::string a = doc.text("allocator");
    s.override_allocator = true;
    if (a == "pinv") {
      s.allocator = gnc::AllocatorKind::kPseudoInverse;
    } else if (a == "l1") {
      s.allocator = gnc::AllocatorKind::kL1;
    } else {
      doc.fail("allocator", "expected pinv or l1, got '" + a + "'");
    }
  }

  if (doc.has("replan")) {
    // The replan strategies' policy (runner.hpp ReplanOptions); every key optional.
    config::MapReader r = doc.map("replan");
    if (r.has("latency_s")) s.replan.latency_s = r.non_negative("latency_s");
    if (r.has("first_plan_s")) s.replan.first_plan_s = r.non_negative("first_plan_s");
    if (r.has("first_plan_max_s")) s.replan.first_plan_max_s = r.non_negative("first_plan_max_s");
    if (r.has("period_s")) s.replan.period_s = r.non_negative("period_s");
    if (r.has("error_fraction")) s.replan.error_fraction = r.non_negative("error_fraction");
    if (r.has("on_model_update")) s.replan.on_model_update = r.boolean("on_model_update");
    if (r.has("min_interval_s")) s.replan.min_interval_s = r.non_negative("min_interval_s");
    if (r.has("horizon_factor")) s.replan.horizon_factor = r.positive("horizon_factor");
    if (r.has("min_horizon_s")) s.replan.min_horizon_s = r.non_negative("min_horizon_s");
    if (r.has("early_plan_s")) s.replan.early_plan_s = r.non_negative("early_plan_s");
    if (r.has("on_identified")) s.replan.on_identified = r.boolean("on_identified");
    if (r.has("early_sigmas")) s.replan.early_sigmas = r.positive("early_sigmas");
    if (r.has("early_j_rel")) s.replan.early_j_rel = r.positive("early_j_rel");
    if (r.has("early_r_m")) s.replan.early_r_m = r.positive("early_r_m");
    if (r.has("refuted_max_s")) s.replan.refuted_max_s = r.non_negative("refuted_max_s");
    if (r.has("adopt_sigmas")) s.replan.adopt_sigmas = r.non_negative("adopt_sigmas");
    if (r.has("adopt_wait_s")) s.replan.adopt_wait_s = r.non_negative("adopt_wait_s");
    if (r.has("adopt_settle_tau")) s.replan.adopt_settle_tau = r.non_negative("adopt_settle_tau");
    if (r.has("offset_confident_m")) {
      s.replan.offset_confident_m = r.non_negative("offset_confident_m");
    }
    if (r.has("slew_s")) s.replan.slew_s = r.non_negative("slew_s");
    if (r.has("momentum_k")) s.replan.momentum_k = r.non_negative("momentum_k");
    if (s.replan.first_plan_max_s < s.replan.first_plan_s) {
      r.fail("first_plan_max_s", "must not be below first_plan_s");
    }
    r.finish();
  }

  if (doc.has("faults")) load_faults(doc.map("faults"), path, s.faults);
  if (!s.faults.case_files.empty()) {
    // Each draw flies a study case file: no dispersed parameters.
    if (doc.has("parameters")) {
      doc.fail("parameters", "must be absent when faults.cases is given (each draw flies its case)");
    }
    s.u_max_n.value = 1.0;
    doc.finish();
    return s;
  }

  MapReader p = doc.map("parameters");
  s.delta_j_norm = scalar(p, "delta_j_ast_norm_kg_m2", false);
  s.delta_j_direction = direction(p, "delta_j_ast_direction", false, true, false);
  if (p.has("max_pd_redraws")) {
    s.max_pd_redraws = p.integer("max_pd_redraws");
    if (s.max_pd_redraws < 0) p.fail("max_pd_redraws", "must not be negative");
  }
  s.delta_r_norm = scalar(p, "delta_r_so_bcm_norm_m", false);
  s.delta_r_direction = direction(p, "delta_r_so_bcm_direction", true, false, false);
  s.initial_rate_norm = scalar(p, "initial_rate_norm_rad_s", false);
  s.initial_rate_direction = direction(p, "initial_rate_direction", true, false, false);
  s.initial_attitude = direction(p, "initial_attitude", false, false, true);
  s.gyro_psd = scalar(p, "gyro_noise_psd_rad2_s2", false);
  s.star_psd = scalar(p, "star_noise_psd", false);
  s.disturbance_sigma_nm = scalar(p, "disturbance_sigma_nm", false);
  {
    const YAML::Node seed = p.get("noise_seed");
    if (seed.IsScalar() && seed.as<std::string>() == "per_draw") {
      s.noise_seed_per_draw = true;
    } else {
      s.noise_seed_per_draw = false;
      s.noise_seed = p.unsigned_integer("noise_seed");
    }
  }
  s.u_max_n = scalar(p, "u_max_n", false);
  if (p.has("thruster_strength_sigma")) {
    s.thruster_strength_sigma = scalar(p, "thruster_strength_sigma", false);
    if (s.thruster_strength_sigma.quantile(1.0) > 0.1) {
      p.fail("thruster_strength_sigma", "above 0.1: a thruster that far off is a fault, not a strength");
    }
  }
  if (p.has("gyro_bias_norm_rad_s")) {
    s.gyro_bias_norm_rad_s = scalar(p, "gyro_bias_norm_rad_s", false);
  }
  if (s.u_max_n.quantile(0.0) <= 0.0 && !(s.u_max_n.kind == Scalar::Kind::kNormal)) {
    p.fail("u_max_n", "must be positive");
  }
  if (s.u_max_n.kind == Scalar::Kind::kNormal && !(s.u_max_n.min > 0.0)) {
    p.fail("u_max_n", "a normal u_max must be truncated at min > 0");
  }
  p.finish();
  doc.finish();
  return s;
}

}  // namespace rocksteady::dispersion
