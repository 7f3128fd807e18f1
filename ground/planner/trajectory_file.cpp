#include "ground/planner/trajectory_file.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rocksteady::ground::planner {

namespace {

constexpr const char* kFormatName = "rocksteady-trajectory";
constexpr const char* kChecksumKey = "checksum: ";

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

std::string hex64(std::uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
}

template <typename Derived>
std::string items(const Eigen::MatrixBase<Derived>& v) {
  std::string s;
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i > 0) s += ", ";
    s += num(v(i));
  }
  return s;
}

template <typename Derived>
std::string row(const Eigen::MatrixBase<Derived>& v) {
  return "[" + items(v) + "]";
}

// A reason for rejecting a file; caught in parse_trajectory_file and prefixed with the file name.
struct Reject : std::runtime_error {
  using std::runtime_error::runtime_error;
};

YAML::Node need(const YAML::Node& parent, const char* key, const std::string& where) {
  const YAML::Node n = parent[key];
  if (!n) throw Reject("missing key '" + where + key + "'");
  return n;
}

double as_double(const YAML::Node& n, const std::string& what) {
  try {
    const double v = n.as<double>();
    if (!std::isfinite(v)) throw Reject(what + " is not finite");
    return v;
  } catch (const YAML::Exception&) {
    throw Reject(what + " is not a number");
  }
}

int as_int(const YAML::Node& n, const std::string& what) {
  try {
    return n.as<int>();
  } catch (const YAML::Exception&) {
    throw Reject(what + " is not an integer");
  }
}

std::uint64_t as_hex(const YAML::Node& n, const std::string& what) {
  try {
    const std::string s = n.as<std::string>();
    std::size_t used = 0;
    const unsigned long long v = std::stoull(s, &used, 16);
    if (used != s.size()) throw Reject(what + " is not a hexadecimal number");
    return v;
  } catch (const YAML::Exception&) {
    throw Reject(what + " is not a hexadecimal number");
  } catch (const std::logic_error&) {
    throw Reject(what + " is not a hexadecimal number");
  }
}

Eigen::VectorXd as_vector(const YAML::Node& n, int size, const std::string& what) {
  if (!n.IsSequence() || static_cast<int>(n.size()) != size) {
    throw Reject(what + " must be a list of " + std::to_string(size) + " numbers");
  }
  Eigen::VectorXd v(size);
  for (int i = 0; i < size; ++i) v[i] = as_double(n[i], what + "[" + std::to_string(i) + "]");
  return v;
}

template <int Rows, int Cols>
Eigen::Matrix<double, Rows, Cols> as_matrix(const YAML::Node& n, const std::string& what) {
  if (!n.IsSequence() || static_cast<int>(n.size()) != Rows) {
    throw Reject(what + " must have " + std::to_string(Rows) + " rows");
  }
  Eigen::Matrix<double, Rows, Cols> m;
  for (int r = 0; r < Rows; ++r) {
    m.row(r) = as_vector(n[r], Cols, what + " row " + std::to_string(r)).transpose();
  }
  return m;
}

template <typename A, typename B>
void require_same(const A& stored, const B& expected, const char* what) {
  const double scale = std::max(1.0, static_cast<double>(expected.norm()));
  const double diff = (stored - expected).norm();
  if (!(diff <= 1e-12 * scale)) {
    std::ostringstream msg;
    msg << "planned for a different model: " << what << " differs from the model given ("
        << diff << " apart)";
    throw Reject(msg.str());
  }
}

void require_same_scalar(double stored, double expected, const char* what) {
  require_same(Eigen::Matrix<double, 1, 1>(stored), Eigen::Matrix<double, 1, 1>(expected), what);
}

}  // namespace

std::uint32_t crc32(const std::string& bytes) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (const char ch : bytes) {
    crc ^= static_cast<unsigned char>(ch);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

gnc::TrajectoryTable TrajectoryFile::to_table() const { return planner::to_table(samples); }

std::string format_trajectory_file(const PlanProblem& problem, const PlanResult& result) {
  if (!result.ok) throw std::runtime_error("refusing to write a failed plan: " + result.error);
  const PlanModel& m = problem.model;
  const PlanSettings& s = problem.settings;
  const gnc::TrajectoryTable table = to_table(result.samples);
  std::ostringstream o;
  o << "# Rocksteady reference trajectory: fuel-optimal despin, SPEC Eq. (44).\n"
    << "# Samples are every Hermite-Simpson collocation point (nodes and interval midpoints).\n"
    << "# The last line is a CRC-32 of every byte above it: edit nothing by hand.\n"
    << "format: " << kFormatName << "\n"
    << "version: " << kTrajectoryFileVersion << "\n"
    << "case: \"" << problem.case_name << "\"\n"
    << "model:  # the estimated model the plan is for (SPEC Eq. 6)\n"
    << "  j_hat: [" << row(m.j_hat.row(0)) << ", " << row(m.j_hat.row(1)) << ", "
    << row(m.j_hat.row(2)) << "]  # kg m^2\n"
    << "  b_hat: [" << row(m.b_hat.row(0)) << ", " << row(m.b_hat.row(1)) << ", "
    << row(m.b_hat.row(2)) << "]  # m\n"
    << "  u_max: " << num(m.u_max) << "  # N\n"
    << "  eps_trans: " << num(m.eps_trans) << "  # rad/s\n"
    << "  omega_init: " << row(m.omega_init) << "  # rad/s\n"
    << "planner:\n"
    << "  transcription: hermite-simpson\n"
    << "  solver: ipopt\n"
    << "  nodes: " << result.nodes << "  # resolved\n"
    << "  grid: " << (s.tumble_grid ? "tumble" : "uniform") << "\n"
    << "  free_final_time: " << (s.free_final_time ? "true" : "false") << "\n"
    << "  t_final_min: " << num(result.t_final_min) << "  # s (resolved)\n"
    << "  t_final_max: " << num(result.t_final_max) << "  # s (resolved)\n"
    << "  tolerance: " << num(s.tolerance) << "\n"
    << "  refinement_check: "
    << (s.refinement_check == PlanSettings::RefinementCheck::kBisect ? "bisect" : "coarsen") << "\n"
    << "  refinement_limit: " << num(s.refinement_limit) << "\n"
    << "  propagation_limit: " << num(s.propagation_limit) << "\n"
    << "  problem_hash: \"" << hex64(problem_hash(problem)) << "\"\n"
    << "result:\n"
    << "  fuel_kg: " << num(result.fuel_kg) << "\n"
    << "  cost_ns: " << num(result.cost_ns) << "  # int |u|_1 dt\n"
    << "  t_final: " << num(result.t_final) << "  # s\n"
    << "  t_active: " << num(result.t_active) << "  # s, end of the despin (at rest after it)\n"
    << "  iterations: " << result.iterations << "\n"
    << "  solve_seconds: " << num(result.solve_seconds) << "\n"
    << "  refined_fuel_kg: " << num(result.verification.refined_fuel_kg) << "\n"
    << "  refined_nodes: " << result.verification.refined_nodes << "  # nodes of the grid check\n"
    << "  max_defect: " << num(result.verification.max_defect) << "  # rad/s\n"
    << "  propagation_error: " << num(result.verification.propagation_error) << "  # rad/s\n"
    << "  table_checksum: \"" << hex32(table.checksum) << "\"  # gnc::trajectory_checksum\n"
    << "samples:  # [t s, omega_d rad/s (3), omega_d_dot rad/s^2 (3), u_d N (8)]\n";
  for (const PlanSample& p : result.samples) {
    o << "  - [" << num(p.t) << ", " << items(p.omega_d) << ", " << items(p.omega_d_dot) << ", "
      << items(p.u_d) << "]\n";
  }
  std::string body = o.str();
  return body + kChecksumKey + "\"" + hex32(crc32(body)) + "\"\n";
}

void write_trajectory_file(const std::string& path, const PlanProblem& problem,
                           const PlanResult& result) {
  const std::string text = format_trajectory_file(problem, result);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": cannot open for writing");
    out << text;
    out.flush();
    if (!out) throw std::runtime_error(path + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error(path + ": cannot move the written file in place: " + ec.message());
}

LoadResult parse_trajectory_file(const std::string& text, const std::string& name,
                                 const PlanModel& expected) {
  LoadResult r;
  try {
    // 1. Content checksum: the last line is `checksum: "0x........"` over every byte before it.
    std::size_t line = text.rfind(std::string("\n") + kChecksumKey);
    if (line == std::string::npos) throw Reject("no checksum line (truncated or not a trajectory file)");
    ++line;
    const std::string body = text.substr(0, line);
    std::string tail = text.substr(line + std::string(kChecksumKey).size());
    while (!tail.empty() && (tail.back() == '\n' || tail.back() == '\r')) tail.pop_back();
    if (tail.size() != 12 || tail.front() != '"' || tail.back() != '"') {
      throw Reject("malformed checksum line");
    }
    std::uint32_t stored = 0;
    try {
      std::size_t used = 0;
      stored = static_cast<std::uint32_t>(std::stoul(tail.substr(1, 10), &used, 16));
      if (used != 10) throw Reject("malformed checksum line");
    } catch (const std::logic_error&) {
      throw Reject("malformed checksum line");
    }
    if (crc32(body) != stored) {
      throw Reject("content checksum mismatch (file altered or corrupted): stored " + hex32(stored) +
                   ", computed " + hex32(crc32(body)));
    }

    // 2. Structure.
    YAML::Node doc;
    try {
      doc = YAML::Load(body);
    } catch (const YAML::Exception& e) {
      throw Reject(std::string("malformed YAML: ") + e.what());
    }
    if (!doc.IsMap()) throw Reject("not a YAML mapping");
    const YAML::Node format = need(doc, "format", "");
    if (!format.IsScalar() || format.as<std::string>() != kFormatName) {
      throw Reject(std::string("format is not '") + kFormatName + "'");
    }
    TrajectoryFile& f = r.file;
    f.version = as_int(need(doc, "version", ""), "version");
    if (f.version != kTrajectoryFileVersion) {
      throw Reject("unsupported version " + std::to_string(f.version) + " (this build reads " +
                   std::to_string(kTrajectoryFileVersion) + ")");
    }
    f.case_name = need(doc, "case", "").as<std::string>();

    const YAML::Node model = need(doc, "model", "");
    f.model.j_hat = as_matrix<3, 3>(need(model, "j_hat", "model."), "model.j_hat");
    f.model.b_hat = as_matrix<3, 8>(need(model, "b_hat", "model."), "model.b_hat");
    f.model.u_max = as_double(need(model, "u_max", "model."), "model.u_max");
    f.model.eps_trans = as_double(need(model, "eps_trans", "model."), "model.eps_trans");
    f.model.omega_init = as_vector(need(model, "omega_init", "model."), 3, "model.omega_init");

    const YAML::Node settings = need(doc, "planner", "");
    f.settings.nodes = as_int(need(settings, "nodes", "planner."), "planner.nodes");
    f.settings.free_final_time = need(settings, "free_final_time", "planner.").as<bool>();
    f.settings.t_final_min = as_double(need(settings, "t_final_min", "planner."), "planner.t_final_min");
    f.settings.t_final_max = as_double(need(settings, "t_final_max", "planner."), "planner.t_final_max");
    f.settings.tolerance = as_double(need(settings, "tolerance", "planner."), "planner.tolerance");
    f.settings.refinement_limit =
        as_double(need(settings, "refinement_limit", "planner."), "planner.refinement_limit");
    // Optional: files written before the coarsening check were checked by bisection.
    if (const YAML::Node check = settings["refinement_check"]) {
      const std::string method = check.IsScalar() ? check.as<std::string>() : std::string();
      if (method == "coarsen") {
        f.settings.refinement_check = PlanSettings::RefinementCheck::kCoarsen;
      } else if (method == "bisect") {
        f.settings.refinement_check = PlanSettings::RefinementCheck::kBisect;
      } else {
        throw Reject("planner.refinement_check: \"" + method + "\" is not coarsen or bisect");
      }
    } else {
      f.settings.refinement_check = PlanSettings::RefinementCheck::kBisect;
    }
    f.settings.propagation_limit =
        as_double(need(settings, "propagation_limit", "planner."), "planner.propagation_limit");
    f.problem_hash = as_hex(need(settings, "problem_hash", "planner."), "planner.problem_hash");

    const YAML::Node result = need(doc, "result", "");
    f.fuel_kg = as_double(need(result, "fuel_kg", "result."), "result.fuel_kg");
    f.cost_ns = as_double(need(result, "cost_ns", "result."), "result.cost_ns");
    f.t_final = as_double(need(result, "t_final", "result."), "result.t_final");
    f.iterations = as_int(need(result, "iterations", "result."), "result.iterations");
    f.solve_seconds = as_double(need(result, "solve_seconds", "result."), "result.solve_seconds");
    const auto table_checksum = static_cast<std::uint32_t>(
        as_hex(need(result, "table_checksum", "result."), "result.table_checksum"));

    const YAML::Node samples = need(doc, "samples", "");
    if (!samples.IsSequence()) throw Reject("samples is not a list");
    if (samples.size() > static_cast<std::size_t>(gnc::kMaxTrajectorySamples)) {
      throw Reject("more samples than the on-board table holds (" +
                   std::to_string(samples.size()) + " > " +
                   std::to_string(gnc::kMaxTrajectorySamples) + ")");
    }
    if (samples.size() != static_cast<std::size_t>(2 * f.settings.nodes - 1)) {
      throw Reject("sample count " + std::to_string(samples.size()) + " does not match " +
                   std::to_string(f.settings.nodes) + " nodes (2N-1 points)");
    }
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const Eigen::VectorXd v = as_vector(samples[i], 15, "samples[" + std::to_string(i) + "]");
      PlanSample s;
      s.t = v[0];
      s.omega_d = v.segment<3>(1);
      s.omega_d_dot = v.segment<3>(4);
      s.u_d = v.segment<8>(7);
      f.samples.push_back(s);
    }

    // 3. The model the plan was made for must be the model we will fly with.
    require_same(f.model.j_hat, expected.j_hat, "j_hat");
    require_same(f.model.b_hat, expected.b_hat, "b_hat");
    require_same_scalar(f.model.u_max, expected.u_max, "u_max");
    require_same_scalar(f.model.eps_trans, expected.eps_trans, "eps_trans");
    require_same(f.model.omega_init, expected.omega_init, "omega_init");

    // 4. The flight-side table: its own checksum and gnc's validation.
    const gnc::TrajectoryTable table = f.to_table();
    if (table.checksum != table_checksum) {
      throw Reject("table checksum mismatch: stored " + hex32(table_checksum) + ", samples give " +
                   hex32(table.checksum));
    }
    const gnc::TrajectoryError e = gnc::validate_trajectory(table, f.model.eps_trans);
    if (e != gnc::TrajectoryError::kOk) {
      throw Reject(std::string("trajectory table rejected: ") + gnc::to_string(e));
    }

    // 5. The samples still solve Eq. (44)'s constraints for this model.
    const Verification v = verify_samples(f.model, f.samples, f.settings.propagation_limit);
    if (!v.passed) throw Reject("samples fail verification: " + v.failure);
    for (std::size_t i = 0; i < f.samples.size(); ++i) {
      const PlanSample& s = f.samples[i];
      const Vec3 j_omega = f.model.j_hat * s.omega_d;
      const Vec3 expected_dot =
          f.model.j_hat.inverse() * (j_omega.cross(s.omega_d) + f.model.b_hat * s.u_d);
      if (!((s.omega_d_dot - expected_dot).norm() <= 1e-9 * (1e-6 + expected_dot.norm()))) {
        throw Reject("samples[" + std::to_string(i) + "]: omega_d_dot is not the model's Eq. (41)");
      }
    }
    r.ok = true;
  } catch (const Reject& e) {
    r.ok = false;
    r.error = name + ": " + e.what();
    r.file = TrajectoryFile{};
  } catch (const YAML::Exception& e) {
    r.ok = false;
    r.error = name + ": malformed content: " + e.what();
    r.file = TrajectoryFile{};
  }
  return r;
}

LoadResult load_trajectory_file(const std::string& path, const PlanModel& expected_model) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    LoadResult r;
    r.error = path + ": cannot open";
    return r;
  }
  std::ostringstream text;
  text << in.rdbuf();
  return parse_trajectory_file(text.str(), path, expected_model);
}

}  // namespace rocksteady::ground::planner
