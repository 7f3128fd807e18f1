// The one error type of configuration loading: which file, which key, why.
#pragma once

#include <stdexcept>
#include <string>

namespace rocksteady::config {

class ConfigError : public std::runtime_error {
 public:
  ConfigError(std::string file, std::string key, std::string reason)
      : std::runtime_error(format(file, key, reason)),
        file_(std::move(file)),
        key_(std::move(key)),
        reason_(std::move(reason)) {}
  const std::string& file() const { return file_; }
  const std::string& key() const { return key_; }
  const std::string& reason() const { return reason_; }

 private:
  static std::string format(const std::string& f, const std::string& k, const std::string& r) {
    return f + ": " + (k.empty() ? std::string() : k + ": ") + r;
  }
  std::string file_;
  std::string key_;
  std::string reason_;
};

}  // namespace rocksteady::config
