// The generated dictionary: every numeric element of every bus type is a point, in .lcm order
// (the .lcm files parsed here, independently of the generator); the flight's names are the
// flight's (fsw::to_string); decoding yields the values that were encoded; limit states follow the
// yellow/red bounds; and the generator refuses an incomplete or inconsistent dictionary.yaml.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "fsw/interface.hpp"
#include "ground/dictionary/dictionary.hpp"

namespace rocksteady::ground::dictionary {
namespace {

// Numeric element names of an .lcm struct in file order (strings left out).
std::vector<std::string> lcm_elements(const std::string& type) {
  std::ifstream in(std::string(ROCKSTEADY_LCM_DIR) + "/" + type + ".lcm");
  EXPECT_TRUE(in.good()) << type;
  std::vector<std::string> names;
  const std::regex field(R"(^\s*(\w+)\s+(\w+)((?:\[\d+\])*)\s*;)");
  const std::regex dim(R"(\[(\d+)\])");
  bool in_struct = false;
  for (std::string line; std::getline(in, line);) {
    if (line.find("//") != std::string::npos) line.resize(line.find("//"));
    if (line.find('{') != std::string::npos) {
      in_struct = true;
      continue;
    }
    if (!in_struct || line.find("const ") != std::string::npos) continue;
    std::smatch m;
    if (!std::regex_search(line, m, field) || m[1] == "string") continue;
    std::vector<int> dims;
    const std::string d = m[3];
    for (auto it = std::sregex_iterator(d.begin(), d.end(), dim); it != std::sregex_iterator();
         ++it) {
      dims.push_back(std::stoi((*it)[1]));
    }
    const std::string name = m[2];
    if (dims.empty()) names.push_back(name);
    if (dims.size() == 1) {
      for (int i = 0; i < dims[0]; ++i) names.push_back(name + "_" + std::to_string(i));
    }
    if (dims.size() == 2) {
      for (int i = 0; i < dims[0]; ++i) {
        for (int j = 0; j < dims[1]; ++j) {
          names.push_back(name + "_" + std::to_string(i) + "_" + std::to_string(j));
        }
      }
    }
  }
  return names;
}

TEST(Dictionary, EveryElementOfEveryBusTypeIsAPointInLcmOrder) {
  const std::vector<std::pair<const char*, const char*>> types{
      {"RS_GNC_TLM", "gnc_telemetry_t"},     {"RS_EVENTS", "event_t"},
      {"RS_CMD_ACK", "cmd_ack_t"},           {"RS_GROUND_CMD", "ground_cmd_t"},
      {"RS_PLANT_TRUTH", "plant_truth_t"},   {"RS_SENSORS", "sensor_frame_t"},
      {"RS_THRUSTER_CMD", "thruster_cmd_t"}, {"RS_TRAJ_UPLINK", "trajectory_chunk_t"},
      {"RS_PARAMS", "param_table_t"},       {"RS_PLANT_FAULT", "plant_fault_cmd_t"}};
  EXPECT_EQ(channels().size(), types.size());
  for (const auto& [channel, type] : types) {
    const Channel* c = find_channel(channel);
    ASSERT_NE(c, nullptr) << channel;
    EXPECT_STREQ(c->type, type);
    std::vector<std::string> keys;
    for (int i = 0; i < c->point_count; ++i) keys.push_back(c->points[i].key);
    EXPECT_EQ(keys, lcm_elements(type)) << channel;
  }
}

TEST(Dictionary, FlightNamesAreTheFlightsOwn) {
  for (int op = 0; op < fsw::kOpcodeCount; ++op) {
    EXPECT_EQ(enum_name("opcode", op), fsw::to_string(static_cast<fsw::Opcode>(op)));
  }
  EXPECT_FALSE(enum_name("opcode", fsw::kOpcodeCount).has_value());
  for (int r = 0; r <= static_cast<int>(fsw::RejectReason::kUploadIncomplete); ++r) {
    EXPECT_EQ(enum_name("reason", r), fsw::to_string(static_cast<fsw::RejectReason>(r)));
  }
  int events_seen = 0;
  for (int id = 100; id <= static_cast<int>(fsw::EventId::kJetCheck); ++id) {
    const EventInfo* e = find_event(id);
    ASSERT_NE(e, nullptr) << id;
    EXPECT_STREQ(e->name, fsw::to_string(static_cast<fsw::EventId>(id)));
    ++events_seen;
  }
  // The rest are the plant's (ids from 1000), none of them the flight's.
  int plant_events = 0;
  for (const EventInfo& e : events()) {
    if (e.id >= 1000) ++plant_events;
  }
  EXPECT_EQ(static_cast<int>(events().size()), events_seen + plant_events);
  EXPECT_EQ(enum_name("event", 1002), "run_finished");
  // The severities the console relies on for its colours.
  EXPECT_STREQ(find_event(static_cast<int>(fsw::EventId::kSensorTimeout))->severity, "ERROR");
  EXPECT_STREQ(find_event(static_cast<int>(fsw::EventId::kCommandRejected))->severity, "WARNING");
  for (int s = 0; s <= 4; ++s) {
    EXPECT_EQ(enum_value("severity", *enum_name("severity", s)), s);
  }
  EXPECT_EQ(enum_name("severity", static_cast<int>(fsw::Severity::kError)), "ERROR");
}

TEST(Dictionary, DecodeReturnsEveryEncodedValue) {
  auto m = wire::make<rocksteady::gnc_telemetry_t>();
  m.t = 12.5;
  m.tick = 125;
  m.mode = 2;
  m.omega_hat[1] = -0.0125;
  m.fuel_kg = 99.75;
  m.rate_group_count = 2;
  m.rg_max_exec_ns[1] = 123456789;
  m.uplink_id = -1;
  m.alloc_scale = 1.0;
  std::vector<unsigned char> buf(static_cast<std::size_t>(m.getEncodedSize()));
  ASSERT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  const Channel* c = find_channel("RS_GNC_TLM");
  ASSERT_NE(c, nullptr);
  std::vector<double> v(static_cast<std::size_t>(c->point_count), -7.0);
  std::string text;
  wire::DecodeStatus st{};
  ASSERT_TRUE(c->decode(buf.data(), static_cast<int>(buf.size()), v.data(), text, st));
  auto at = [&](const char* key) { return v[static_cast<std::size_t>(find_point(*c, key))]; };
  EXPECT_EQ(at("t"), 12.5);
  EXPECT_EQ(at("tick"), 125.0);
  EXPECT_EQ(at("omega_hat_1"), -0.0125);
  EXPECT_EQ(at("omega_hat_0"), 0.0);
  EXPECT_EQ(at("fuel_kg"), 99.75);
  EXPECT_EQ(at("rg_max_exec_ns_1"), 123456789.0);
  EXPECT_EQ(at("uplink_id"), -1.0);
  EXPECT_EQ(format_value(c->points[find_point(*c, "mode")], at("mode")), "HOLD");
  // A truncated message is refused, not guessed at.
  EXPECT_FALSE(c->decode(buf.data(), static_cast<int>(buf.size()) - 1, v.data(), text, st));
  EXPECT_EQ(st, wire::DecodeStatus::kTooShort);

  auto e = wire::make<rocksteady::event_t>();
  e.severity = 3;
  e.id = 104;
  e.text = "sensor timeout -> SAFE";
  buf.assign(static_cast<std::size_t>(e.getEncodedSize()), 0);
  e.encode(buf.data(), 0, static_cast<int>(buf.size()));
  const Channel* ec = find_channel("RS_EVENTS");
  ASSERT_TRUE(ec->has_text);
  v.assign(static_cast<std::size_t>(ec->point_count), 0.0);
  ASSERT_TRUE(ec->decode(buf.data(), static_cast<int>(buf.size()), v.data(), text, st));
  EXPECT_EQ(text, e.text);
  EXPECT_EQ(format_value(ec->points[find_point(*ec, "id")], 104.0), "sensor_timeout");
}

TEST(Dictionary, LimitLevelsFollowTheBounds) {
  const Channel* c = find_channel("RS_GNC_TLM");
  const Point& mode = c->points[find_point(*c, "mode")];
  EXPECT_EQ(limit_level(mode, 2.0), 0);  // HOLD
  EXPECT_EQ(limit_level(mode, 4.0), 2);  // SAFE is red
  const Point& w = c->points[find_point(*c, "omega_hat_2")];
  ASSERT_TRUE(std::isfinite(w.yellow_hi) && std::isfinite(w.red_hi));
  EXPECT_LT(w.yellow_hi, w.red_hi);
  EXPECT_EQ(limit_level(w, 0.0), 0);
  EXPECT_EQ(limit_level(w, 0.5 * (w.yellow_hi + w.red_hi)), 1);
  EXPECT_EQ(limit_level(w, -0.5 * (w.yellow_hi + w.red_hi)), 1);
  EXPECT_EQ(limit_level(w, 2.0 * w.red_hi), 2);
  EXPECT_EQ(limit_level(w, std::nan("")), 2);
  const Point& tick = c->points[find_point(*c, "tick")];
  EXPECT_EQ(limit_level(tick, 1e18), 0);  // no limits
}

TEST(Dictionary, JsonHasEveryChannel) {
  for (const Channel& c : channels()) {
    EXPECT_NE(json_text().find(std::string("\"channel\":\"") + c.channel + "\""),
              std::string::npos);
  }
}

// Runs the generator on a copy of dictionary.yaml with one line changed; returns exit status and
// its standard error.
std::pair<int, std::string> dictgen_with(const std::string& from, const std::string& to) {
  std::ifstream in(ROCKSTEADY_DICTIONARY_YAML);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string yaml = ss.str();
  const std::size_t at = yaml.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  yaml.replace(at, from.size(), to);
  const std::string dir = ::testing::TempDir() + "dictgen_" +
                          std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                          std::to_string(std::hash<std::string>{}(from + to));
  std::system(("mkdir -p " + dir).c_str());
  std::ofstream(dir + "/d.yaml") << yaml;
  const std::string cmd = std::string(ROCKSTEADY_DICTGEN_EXE) + " " + dir + "/d.yaml " + dir + " " +
                          ROCKSTEADY_LCM_DIR + "/*.lcm 2> " + dir + "/err";
  const int rc = std::system(cmd.c_str());
  std::stringstream es;
  {
    std::ifstream err(dir + "/err");
    es << err.rdbuf();
  }
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);  // the copy, the generated files and the log
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, es.str()};
}

TEST(Dictgen, RefusesAFieldWithoutAnEntry) {
  const auto [rc, err] = dictgen_with("      fuel_kg: {units: kg,", "      fuel_kgx: {units: kg,");
  EXPECT_EQ(rc, 2);
  EXPECT_NE(err.find("types.gnc_telemetry_t.fields.fuel_kgx: gnc_telemetry_t has no such field"),
            std::string::npos)
      << err;
}

TEST(Dictgen, RefusesAnEventWithoutSeverityAndABadLimit) {
  {
    const auto [rc, err] = dictgen_with("  overrun_safe: ERROR\n", "");
    EXPECT_EQ(rc, 2);
    EXPECT_NE(err.find("events: the flight's event 'overrun_safe' (124) has no severity"),
              std::string::npos)
        << err;
  }
  {
    const auto [rc, err] = dictgen_with("red: [null, 3.5]", "red: [4, 3.5]");
    EXPECT_EQ(rc, 2);
    EXPECT_NE(err.find("types.gnc_telemetry_t.fields.mode.red: low bound must be below"),
              std::string::npos)
        << err;
  }
}

TEST(Dictgen, AcceptsTheCheckedInDictionary) {
  const auto [rc, err] = dictgen_with("# Rocksteady's", "# Rocksteady's");
  EXPECT_EQ(rc, 0) << err;
}

}  // namespace
}  // namespace rocksteady::ground::dictionary
