// Helpers of the ground CLI tests: a private temporary directory and running a command line.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace rocksteady::ground::cli::test {

class TempDir {
 public:
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "rs-ground-cli-XXXXXX").string();
    if (mkdtemp(tmpl.data()) == nullptr) std::abort();
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

inline std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Run {
  int exit_code{-1};
  std::string out;  // standard output
  std::string err;  // standard error
};

// Runs `command` with /bin/sh, capturing stdout and stderr into files of `dir`.
inline Run run(const std::string& command, const TempDir& dir) {
  const std::string out = dir.file("stdout.txt");
  const std::string err = dir.file("stderr.txt");
  const std::string full = "(" + command + ") >'" + out + "' 2>'" + err + "'";
  const int status = std::system(full.c_str());
  Run r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(out);
  r.err = read_file(err);
  return r;
}

// Single quotes for /bin/sh.
inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (const char c : s) {
    if (c == '\'') {
      q += "'\\''";
    } else {
      q += c;
    }
  }
  return q + "'";
}

// Runs `script` with /bin/sh in a fresh network namespace whose loopback carries the LCM multicast
// group (ENVIRONMENT.md), bounded by `timeout`. Exit 90: the namespace could not be set up.
inline Run run_in_namespace(const std::string& script, const TempDir& dir, int timeout_s = 60) {
  const std::string s =
      "ip link set lo up && ip link set lo multicast on && ip route add 239.255.76.67 dev lo || "
      "exit 90\n"
      // The stand-in flight (test_responder) does not authenticate: the ground is in lab mode
      // unless a script gives --key-file (fsw_net_test.cpp does, against the real flight).
      "export ROCKSTEADY_LAB_MODE=1\n" +
      script;
  return run("timeout " + std::to_string(timeout_s) + " unshare -rn sh -c " + quote(s), dir);
}

inline std::string lcm_url(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
}

}  // namespace rocksteady::ground::cli::test
