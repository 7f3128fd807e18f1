#include "ground/config/config_dir.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace rocksteady::config {

namespace fs = std::filesystem;

namespace {

bool is_config_dir(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p / "mission.yaml", ec) && fs::is_regular_file(p / "gnc.yaml", ec);
}

std::vector<int> case_numbers(const std::string& dir) {
  std::vector<int> n;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(fs::path(dir) / "cases", ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("case", 0) == 0 && e.path().extension() == ".yaml") {
      const std::string num = name.substr(4, name.size() - 9);
      if (!num.empty() && std::all_of(num.begin(), num.end(), ::isdigit))
        n.push_back(std::stoi(num));
    }
  }
  std::sort(n.begin(), n.end());
  return n;
}

}  // namespace

ConfigDir find_config_dir(const std::string& given) {
  ConfigDir r;
  if (!given.empty()) {
    if (is_config_dir(given)) {
      r.path = given;
    } else {
      r.error = "--config-dir " + given + ": no mission.yaml and gnc.yaml there";
    }
    return r;
  }
  std::vector<std::pair<std::string, fs::path>> tried;
  if (const char* env = std::getenv("ROCKSTEADY_CONFIG_DIR"); env != nullptr && env[0] != '\0') {
    if (is_config_dir(env)) {
      r.path = env;
      return r;
    }
    r.error = "ROCKSTEADY_CONFIG_DIR=" + std::string(env) + ": no mission.yaml and gnc.yaml there";
    return r;
  }
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    tried.emplace_back("next to the program", exe.parent_path() / "configs");
    tried.emplace_back("installed",
                       exe.parent_path().parent_path() / "share" / "rocksteady" / "configs");
  }
  tried.emplace_back("current directory", fs::path("configs"));
  for (const auto& [what, p] : tried) {
    if (is_config_dir(p)) {
      r.path = p.string();
      return r;
    }
  }
  r.error =
      "no configuration folder (mission.yaml, gnc.yaml, cases/): give --config-dir or set "
      "ROCKSTEADY_CONFIG_DIR; tried";
  for (const auto& [what, p] : tried) r.error += " " + p.string() + " (" + what + ")";
  return r;
}

std::string case_file(const std::string& config_dir, const std::string& value,
                      const std::string& option) {
  const bool number = !value.empty() && std::all_of(value.begin(), value.end(), ::isdigit);
  if (!number) {
    if (!fs::is_regular_file(value))
      throw std::runtime_error(option + " " + value + ": no such file");
    return value;
  }
  const fs::path p = fs::path(config_dir) / "cases" / ("case" + value + ".yaml");
  if (!fs::is_regular_file(p)) {
    std::string have;
    const std::vector<int> n = case_numbers(config_dir);
    if (!n.empty())
      have = " (cases here: " + std::to_string(n.front()) + ".." + std::to_string(n.back()) + ")";
    throw std::runtime_error(option + " " + value + ": no case file " + p.string() + have);
  }
  return p.string();
}

std::string mission_file(const std::string& config_dir) {
  const fs::path p = fs::path(config_dir) / "mission.yaml";
  if (!fs::is_regular_file(p)) throw std::runtime_error(p.string() + ": cannot read file");
  return p.string();
}

std::string gnc_file(const std::string& config_dir) {
  const fs::path p = fs::path(config_dir) / "gnc.yaml";
  if (!fs::is_regular_file(p)) throw std::runtime_error(p.string() + ": cannot read file");
  return p.string();
}

}  // namespace rocksteady::config
