// Shared helpers of the dispersion tests: a dispersion file written from text.
#pragma once

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <string>

namespace rocksteady::dispersion::test {

// This process's scratch directory, removed with everything in it when the process exits (one
// per process: ctest runs each test in a process of its own).
inline const std::filesystem::path& temp_dir() {
  struct Scratch {
    std::filesystem::path dir = std::filesystem::temp_directory_path() /
                                ("rs_dispersion_tests_" + std::to_string(::getpid()));
    ~Scratch() {
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
    }
  };
  static const Scratch scratch;
  return scratch.dir;
}

inline std::string write_temp(const std::string& name, const std::string& text) {
  const std::filesystem::path& dir = temp_dir();
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

inline std::string source(const std::string& rel) {
  return std::string(ROCKSTEADY_SOURCE_DIR) + "/" + rel;
}

// A valid file; tests replace one line to make it malformed.
inline std::string base_spec() {
  return "name: t\n"
         "draws: 10\n"
         "master_seed: 7\n"
         "sampling: random\n"
         "duration_s: 100.0\n"
         "strategies: [dpd, ntcl+dpd_ref]\n"
         "parameters:\n"
         "  delta_j_ast_norm_kg_m2: {distribution: log_uniform, min: 1.0e3, max: 1.0e7}\n"
         "  delta_j_ast_direction: random_symmetric\n"
         "  delta_r_so_bcm_norm_m: {distribution: uniform, min: 0.0, max: 1.0}\n"
         "  delta_r_so_bcm_direction: sphere\n"
         "  initial_rate_norm_rad_s: {distribution: uniform, min: 0.03, max: 0.045}\n"
         "  initial_rate_direction: sphere\n"
         "  initial_attitude: random_rotation\n"
         "  gyro_noise_psd_rad2_s2: {distribution: log_uniform, min: 1.0e-14, max: 1.0e-10}\n"
         "  star_noise_psd: {distribution: log_uniform, min: 1.0e-10, max: 1.0e-6}\n"
         "  disturbance_sigma_nm: {distribution: normal, mean: 0.577, sigma: 0.15, min: 0.0, max: "
         "1.2}\n"
         "  noise_seed: per_draw\n"
         "  u_max_n: {distribution: uniform, min: 200.0, max: 1000.0}\n";
}

inline std::string replace_line(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  if (pos == std::string::npos) return text + "#NOT FOUND " + from;
  text.replace(pos, from.size(), to);
  return text;
}

}  // namespace rocksteady::dispersion::test
