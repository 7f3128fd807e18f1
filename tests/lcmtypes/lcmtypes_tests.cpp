// The bus types: one struct per .lcm file, sizes below the fragmentation limit, distinct fingerprints,
// and the lcm-spy jar (a class per .lcm struct, with the C++ fingerprint).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "lcmtypes/channels.hpp"
#include "rocksteady/cmd_ack_t.hpp"
#include "rocksteady/event_t.hpp"
#include "rocksteady/gnc_telemetry_t.hpp"
#include "rocksteady/ground_cmd_t.hpp"
#include "rocksteady/plant_fault_cmd_t.hpp"
#include "rocksteady/plant_truth_t.hpp"
#include "rocksteady/sensor_frame_t.hpp"
#include "rocksteady/thruster_cmd_t.hpp"
#include "rocksteady/param_table_t.hpp"
#include "rocksteady/trajectory_chunk_t.hpp"

namespace {

struct TypeInfo {
  std::int64_t hash;
  int base_size;  // encoded size with empty strings, fingerprint included
  int kind;
};

template <class T> TypeInfo info() {
  return {T::getHash(), T{}.getEncodedSize(), int{T::KIND}};
}

// The C++ side of every type, by "package.name".
std::map<std::string, TypeInfo> cpp_types() {
  return {
      {"rocksteady.sensor_frame_t", info<rocksteady::sensor_frame_t>()},
      {"rocksteady.thruster_cmd_t", info<rocksteady::thruster_cmd_t>()},
      {"rocksteady.gnc_telemetry_t", info<rocksteady::gnc_telemetry_t>()},
      {"rocksteady.event_t", info<rocksteady::event_t>()},
      {"rocksteady.ground_cmd_t", info<rocksteady::ground_cmd_t>()},
      {"rocksteady.cmd_ack_t", info<rocksteady::cmd_ack_t>()},
      {"rocksteady.plant_truth_t", info<rocksteady::plant_truth_t>()},
      {"rocksteady.trajectory_chunk_t", info<rocksteady::trajectory_chunk_t>()},
      {"rocksteady.param_table_t", info<rocksteady::param_table_t>()},
      {"rocksteady.plant_fault_cmd_t", info<rocksteady::plant_fault_cmd_t>()},
  };
}

struct LcmFile {
  std::string stem;
  std::string package;
  std::vector<std::string> structs;
};

// Parses the .lcm sources themselves (the independent truth for what the jar must hold).
std::vector<LcmFile> lcm_files() {
  std::vector<LcmFile> files;
  const std::regex package_re(R"(^\s*package\s+([A-Za-z_][\w.]*)\s*;)");
  const std::regex struct_re(R"(^\s*struct\s+([A-Za-z_]\w*))");
  for (const auto& entry : std::filesystem::directory_iterator(ROCKSTEADY_LCM_DIR)) {
    if (entry.path().extension() != ".lcm") continue;
    LcmFile f;
    f.stem = entry.path().stem().string();
    std::ifstream in(entry.path());
    std::string line;
    std::smatch m;
    while (std::getline(in, line)) {
      if (std::regex_search(line, m, package_re)) f.package = m[1];
      if (std::regex_search(line, m, struct_re)) f.structs.push_back(m[1]);
    }
    files.push_back(f);
  }
  return files;
}

std::string run(const std::string& command) {
  std::string out;
  FILE* p = popen(command.c_str(), "r");
  if (p == nullptr) return out;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  EXPECT_EQ(pclose(p), 0) << command;
  return out;
}

TEST(LcmTypes, OneStructPerFileNamedAfterTheFile) {
  const auto files = lcm_files();
  ASSERT_EQ(files.size(), cpp_types().size());
  for (const LcmFile& f : files) {
    ASSERT_EQ(f.structs.size(), 1u) << f.stem;
    EXPECT_EQ(f.structs[0], f.stem);
    EXPECT_EQ(f.package, "rocksteady") << f.stem;
    EXPECT_EQ(cpp_types().count(f.package + "." + f.stem), 1u) << f.stem;
  }
}

TEST(LcmTypes, FingerprintsAndKindsAreDistinctAndSizesFitOneDatagram) {
  std::set<std::int64_t> hashes;
  std::set<int> kinds;
  for (const auto& [name, t] : cpp_types()) {
    hashes.insert(t.hash);
    kinds.insert(t.kind);
    // Well under LCM's ~65 KB fragmentation threshold (strings add at most 256 bytes).
    EXPECT_LT(t.base_size + 256, 8192) << name;
    std::cout << "  " << name << ": " << t.base_size << " bytes, fingerprint " << std::hex
              << static_cast<std::uint64_t>(t.hash) << std::dec << "\n";
  }
  EXPECT_EQ(hashes.size(), cpp_types().size());
  EXPECT_EQ(kinds.size(), cpp_types().size());
}

TEST(LcmTypes, FixedSizeTypesDoNotGrowWithContent) {
  // The flight side's messages have no variable-length fields: a filled message has the same size.
  rocksteady::trajectory_chunk_t c{};
  c.count = rocksteady::trajectory_chunk_t::SAMPLES;
  EXPECT_EQ(c.getEncodedSize(), rocksteady::trajectory_chunk_t{}.getEncodedSize());
  rocksteady::ground_cmd_t g{};
  g.nargs = rocksteady::ground_cmd_t::MAX_ARGS;
  EXPECT_EQ(g.getEncodedSize(), rocksteady::ground_cmd_t{}.getEncodedSize());
}

#ifdef ROCKSTEADY_TYPES_JAR

TEST(SpyJar, HasAClassForEveryLcmStructAndNothingElse) {
  const std::string listing = run(std::string("\"") + ROCKSTEADY_JAR_EXE + "\" tf \"" + ROCKSTEADY_TYPES_JAR + "\"");
  std::set<std::string> classes;
  std::istringstream in(listing);
  std::string line;
  while (std::getline(in, line)) {
    if (line.size() > 6 && line.compare(line.size() - 6, 6, ".class") == 0) {
      classes.insert(line.substr(0, line.size() - 6));
    }
  }
  std::set<std::string> expected;
  for (const LcmFile& f : lcm_files()) {
    for (const std::string& s : f.structs) expected.insert(f.package + "/" + s);
  }
  EXPECT_EQ(classes, expected);
}

TEST(SpyJar, JavaFingerprintsEqualTheCppOnesAndLcmSpyResolvesThem) {
  std::string command = std::string("\"") + ROCKSTEADY_JAVA_EXE + "\" -cp \"" + ROCKSTEADY_TYPES_JAR +
                        ":" + ROCKSTEADY_LCM_JAR + ":" + ROCKSTEADY_DUMP_DIR + "\" FingerprintDump";
  const auto types = cpp_types();
  for (const auto& entry : types) command += " " + entry.first;
  const std::string out = run(command);
  std::istringstream lines(out);
  std::string line;
  std::size_t seen = 0;
  while (std::getline(lines, line)) {
    std::istringstream in(line);
    std::string name;
    std::string hex;
    std::string resolved;
    // lcm-spy's type database prints its own progress lines; ours start with the package name.
    if (line.rfind("rocksteady.", 0) != 0 || !(in >> name >> hex >> resolved)) continue;
    ASSERT_EQ(types.count(name), 1u) << name;
    EXPECT_EQ(std::stoull(hex, nullptr, 16), static_cast<std::uint64_t>(types.at(name).hash)) << name;
    // What lcm-spy does with a packet: fingerprint -> class, found by scanning the class path.
    EXPECT_EQ(resolved, name);
    ++seen;
  }
  EXPECT_EQ(seen, types.size());
}

#endif

}  // namespace
