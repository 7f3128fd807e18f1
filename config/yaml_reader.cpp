#include "config/yaml_reader.hpp"

#include <cmath>
#include <fstream>
#include <limits>

namespace rocksteady::config {

YAML::Node load_yaml_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path, "", "cannot read file");
  try {
    YAML::Node doc = YAML::Load(in);
    if (!doc.IsDefined() || doc.IsNull()) throw ConfigError(path, "", "file is empty");
    return doc;
  } catch (const YAML::ParserException& e) {
    throw ConfigError(path, "", "YAML syntax error at line " + std::to_string(e.mark.line + 1) +
                                    ": " + e.msg);
  }
}

MapReader::MapReader(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {
  if (!node_.IsMap()) {
    throw ConfigError(file_, path_.empty() ? "(document)" : path_,
                      "expected a mapping of keys" + line_of(node_));
  }
  // yaml-cpp keeps both entries of a repeated key and lookups see only the first: an error here.
  std::set<std::string> seen;
  for (const auto& kv : node_) {
    const std::string k = kv.first.as<std::string>();
    if (!seen.insert(k).second) fail(k, "duplicate key" + line_of(kv.first));
  }
}

std::string MapReader::key_path(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

std::string MapReader::line_of(const YAML::Node& n) const {
  const YAML::Mark m = n.Mark();
  if (m.line < 0) return "";
  return " (line " + std::to_string(m.line + 1) + ")";
}

void MapReader::fail(const std::string& key, const std::string& reason) const {
  throw ConfigError(file_, key_path(key), reason);
}

bool MapReader::has(const std::string& key) const {
  for (const auto& kv : node_) {
    if (kv.first.as<std::string>() == key) return true;
  }
  return false;
}

YAML::Node MapReader::get(const std::string& key) {
  for (const auto& kv : node_) {
    if (kv.first.as<std::string>() == key) {
      read_.insert(key);
      return kv.second;
    }
  }
  fail(key, "missing required key" + line_of(node_));
}

MapReader MapReader::map(const std::string& key) {
  const YAML::Node n = get(key);
  if (!n.IsMap()) fail(key, "expected a mapping" + line_of(n));
  return MapReader(n, file_, key_path(key));
}

double MapReader::scalar(const YAML::Node& n, const std::string& key) const {
  if (!n.IsScalar()) fail(key, "expected a number" + line_of(n));
  double v = 0.0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    fail(key, "expected a number, got '" + n.Scalar() + "'" + line_of(n));
  }
  if (!std::isfinite(v)) fail(key, "must be finite" + line_of(n));
  return v;
}

double MapReader::number(const std::string& key) { return scalar(get(key), key); }

double MapReader::positive(const std::string& key) {
  const double v = number(key);
  if (!(v > 0.0)) fail(key, "must be positive, got " + std::to_string(v));
  return v;
}

double MapReader::non_negative(const std::string& key) {
  const double v = number(key);
  if (v < 0.0) fail(key, "must not be negative, got " + std::to_string(v));
  return v;
}

int MapReader::integer(const std::string& key) {
  const double v = number(key);
  if (v != std::floor(v) || std::fabs(v) > 1e9) fail(key, "expected an integer");
  return static_cast<int>(v);
}

std::uint64_t MapReader::unsigned_integer(const std::string& key) {
  const YAML::Node n = get(key);
  if (!n.IsScalar()) fail(key, "expected a non-negative integer" + line_of(n));
  try {
    const std::string s = n.Scalar();
    if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos) throw std::exception();
    return n.as<std::uint64_t>();
  } catch (const std::exception&) {
    fail(key, "expected a non-negative integer, got '" + n.Scalar() + "'" + line_of(n));
  }
}

bool MapReader::boolean(const std::string& key) {
  const YAML::Node n = get(key);
  try {
    if (n.IsScalar()) return n.as<bool>();
  } catch (const YAML::Exception&) {
  }
  fail(key, "expected true or false" + line_of(n));
}

std::string MapReader::text(const std::string& key) {
  const YAML::Node n = get(key);
  if (!n.IsScalar()) fail(key, "expected a string" + line_of(n));
  return n.Scalar();
}

Eigen::VectorXd MapReader::list(const std::string& key, int size) {
  const YAML::Node n = get(key);
  if (!n.IsSequence() || static_cast<int>(n.size()) != size) {
    fail(key, "expected a list of " + std::to_string(size) + " numbers" + line_of(n));
  }
  Eigen::VectorXd v(size);
  for (int i = 0; i < size; ++i) v(i) = scalar(n[static_cast<std::size_t>(i)], key);
  return v;
}

Eigen::Vector3d MapReader::vec3(const std::string& key) { return list(key, 3); }

Eigen::Matrix3d MapReader::matrix3(const std::string& key) {
  const YAML::Node n = get(key);
  const std::string shape = "expected a number, a list of 3 numbers or a 3x3 matrix";
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  if (n.IsScalar()) {
    m = scalar(n, key) * Eigen::Matrix3d::Identity();
  } else if (n.IsSequence() && n.size() == 3 && n[0].IsScalar()) {
    for (std::size_t i = 0; i < 3; ++i) m(i, i) = scalar(n[i], key);
  } else if (n.IsSequence() && n.size() == 3) {
    for (std::size_t i = 0; i < 3; ++i) {
      if (!n[i].IsSequence() || n[i].size() != 3) fail(key, shape + line_of(n[i]));
      for (std::size_t j = 0; j < 3; ++j) m(i, j) = scalar(n[i][j], key);
    }
  } else {
    fail(key, shape + line_of(n));
  }
  if ((m - m.transpose()).norm() > 1e-9 * (1.0 + m.norm())) fail(key, "matrix is not symmetric");
  return m;
}

bool MapReader::skip(const std::string& key) {
  if (!has(key)) return false;
  read_.insert(key);
  return true;
}

void MapReader::finish() const {
  for (const auto& kv : node_) {
    const std::string k = kv.first.as<std::string>();
    if (read_.count(k) == 0) fail(k, "unknown key" + line_of(kv.first));
  }
}

}  // namespace rocksteady::config
