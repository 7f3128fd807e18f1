// A strict reader over a YAML mapping: every key must be known (read), every required key present,
// every value of the right shape. Errors are ConfigError with the file, the dotted key and the line.
#pragma once

#include <cstdint>
#include <set>
#include <string>

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include "config/config_error.hpp"

namespace rocksteady::config {

// Parses a whole file (unreadable or malformed: ConfigError).
YAML::Node load_yaml_file(const std::string& path);

class MapReader {
 public:
  // `node` must be a mapping; `path` is the dotted key of the mapping ("" for the document).
  MapReader(YAML::Node node, std::string file, std::string path);

  bool has(const std::string& key) const;
  YAML::Node get(const std::string& key);  // required; marks the key as read
  MapReader map(const std::string& key);
  double number(const std::string& key);
  double positive(const std::string& key);      // > 0
  double non_negative(const std::string& key);  // >= 0
  int integer(const std::string& key);
  std::uint64_t unsigned_integer(const std::string& key);
  bool boolean(const std::string& key);
  std::string text(const std::string& key);
  Eigen::Vector3d vec3(const std::string& key);
  Eigen::VectorXd list(const std::string& key, int size);
  // A number (times I), a list of 3 (diagonal) or a 3x3 matrix; must be symmetric.
  Eigen::Matrix3d matrix3(const std::string& key);
  // Marks a key as read without interpreting it (a key another loader owns). False when absent.
  bool skip(const std::string& key);
  // Every key present must have been read.
  void finish() const;

  [[noreturn]] void fail(const std::string& key, const std::string& reason) const;
  const std::string& file() const { return file_; }
  std::string key_path(const std::string& key) const;

 private:
  double scalar(const YAML::Node& n, const std::string& key) const;
  std::string line_of(const YAML::Node& n) const;

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> read_;
};

}  // namespace rocksteady::config
