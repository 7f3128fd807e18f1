#include "ground/cli/trajectory_input.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace rocksteady::ground::cli {

namespace {

void flatten(const YAML::Node& n, std::vector<double>& out) {
  if (n.IsSequence()) {
    for (const YAML::Node& c : n) flatten(c, out);
  } else {
    out.push_back(n.as<double>());
  }
}

std::vector<double> numbers(const YAML::Node& model, const char* key, std::size_t expected,
                            const std::string& name) {
  const YAML::Node n = model[key];
  if (!n) throw std::runtime_error(name + ": model." + key + " is missing");
  std::vector<double> v;
  try {
    flatten(n, v);
  } catch (const YAML::Exception&) {
    throw std::runtime_error(name + ": model." + key + " is not numeric");
  }
  if (v.size() != expected) {
    throw std::runtime_error(name + ": model." + key + " has " + std::to_string(v.size()) +
                             " numbers, " + std::to_string(expected) + " expected");
  }
  return v;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

planner::PlanModel file_model(const std::string& text, const std::string& name) {
  YAML::Node doc;
  try {
    doc = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(name + ": not YAML: " + e.what());
  }
  const YAML::Node model = doc["model"];
  if (!model || !model.IsMap()) throw std::runtime_error(name + ": no model section");
  planner::PlanModel m;
  const std::vector<double> j = numbers(model, "j_hat", 9, name);
  const std::vector<double> b = numbers(model, "b_hat", 24, name);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m.j_hat(r, c) = j[static_cast<std::size_t>(3 * r + c)];
    for (int c = 0; c < 8; ++c) m.b_hat(r, c) = b[static_cast<std::size_t>(8 * r + c)];
  }
  m.u_max = numbers(model, "u_max", 1, name)[0];
  m.eps_trans = numbers(model, "eps_trans", 1, name)[0];
  const std::vector<double> w = numbers(model, "omega_init", 3, name);
  m.omega_init = planner::Vec3(w[0], w[1], w[2]);
  return m;
}

planner::LoadResult load_trajectory(const std::string& path, const planner::PlanModel& model) {
  return planner::load_trajectory_file(path, model);
}

planner::LoadResult load_trajectory_own_model(const std::string& path) {
  planner::LoadResult r;
  try {
    const std::string text = read_text(path);
    return planner::parse_trajectory_file(text, path, file_model(text, path));
  } catch (const std::exception& e) {
    r.ok = false;
    r.error = e.what();
  }
  return r;
}

}  // namespace rocksteady::ground::cli
