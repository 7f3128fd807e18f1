// log2csv: an LCM log written here with lcm::LogFile (telemetry, truth, an event, and garbage on
// the telemetry channel) converts to CSV whose header is the .lcm file's fields (parsed here,
// independently of the converter) and whose values are the messages'; the garbage is counted.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "fsw/interface.hpp"
#include "ground/cli/csv.hpp"
#include "ground/cli/dictionary.hpp"
#include "test_util.hpp"

namespace rocksteady::ground::cli {
namespace {

// (the bus library is rocksteady::wire)

// Field names of an .lcm struct in file order, arrays expanded (name_i, name_i_j); constants
// skipped.
std::vector<std::string> lcm_fields(const std::string& type) {
  std::ifstream in(std::string(ROCKSTEADY_LCM_DIR) + "/" + type + ".lcm");
  EXPECT_TRUE(in.good()) << type;
  std::vector<std::string> names;
  bool in_struct = false;
  const std::regex field(R"(^\s*\w+\s+(\w+)((?:\[\d+\])*)\s*;)");
  const std::regex dim(R"(\[(\d+)\])");
  for (std::string line; std::getline(in, line);) {
    const std::size_t comment = line.find("//");
    if (comment != std::string::npos) line.resize(comment);
    if (line.find('{') != std::string::npos) {
      in_struct = true;
      continue;
    }
    if (line.find('}') != std::string::npos) break;
    if (!in_struct || line.find("const ") != std::string::npos) continue;
    std::smatch m;
    if (!std::regex_search(line, m, field)) continue;
    std::vector<int> dims;
    const std::string d = m[2];
    for (auto it = std::sregex_iterator(d.begin(), d.end(), dim); it != std::sregex_iterator();
         ++it) {
      dims.push_back(std::stoi((*it)[1]));
    }
    const std::string name = m[1];
    if (dims.empty()) {
      names.push_back(name);
    } else if (dims.size() == 1) {
      for (int i = 0; i < dims[0]; ++i) names.push_back(name + "_" + std::to_string(i));
    } else {
      for (int i = 0; i < dims[0]; ++i) {
        for (int j = 0; j < dims[1]; ++j) {
          names.push_back(name + "_" + std::to_string(i) + "_" + std::to_string(j));
        }
      }
    }
  }
  return names;
}

// A CSV header: every field of the message in .lcm order, then only "<column>_name" columns (the
// dictionary's names of enum fields), each naming a column before it.
void expect_fields_then_names(const std::vector<std::string>& header,
                              const std::vector<std::string>& fields) {
  ASSERT_GE(header.size(), fields.size());
  EXPECT_EQ(std::vector<std::string>(header.begin(),
                                     header.begin() + static_cast<std::ptrdiff_t>(fields.size())),
            fields);
  for (std::size_t i = fields.size(); i < header.size(); ++i) {
    const std::string& h = header[i];
    ASSERT_GT(h.size(), 5u) << h;
    ASSERT_EQ(h.substr(h.size() - 5), "_name") << h;
    EXPECT_NE(std::find(fields.begin(), fields.end(), h.substr(0, h.size() - 5)), fields.end())
        << h;
  }
}

// RFC 4180 fields of one line (no line break inside).
std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        cells.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        cells.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      cells.emplace_back();
    } else {
      cells.back() += c;
    }
  }
  return cells;
}

std::vector<std::vector<std::string>> parse_csv(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) rows.push_back(split_csv(line));
  return rows;
}

std::size_t column(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return i;
  }
  ADD_FAILURE() << "no column " << name;
  return 0;
}

template <class T>
std::vector<unsigned char> bytes(const T& m) {
  std::vector<unsigned char> b(static_cast<std::size_t>(m.getEncodedSize()));
  EXPECT_EQ(wire::encode(m, b.data(), static_cast<int>(b.size())), static_cast<int>(b.size()));
  return b;
}

rocksteady::gnc_telemetry_t telemetry(int k) {
  auto m = wire::make<rocksteady::gnc_telemetry_t>();
  m.t = 0.1 * k + 1.0 / 3.0;  // not a short decimal: the CSV must round-trip doubles exactly
  m.tick = 10 + k;
  m.mode = 2;
  m.law = static_cast<std::int8_t>(k);
  m.omega_hat[1] = -1e-3 * (k + 1);
  m.fuel_kg = 100.0 - k;
  m.rate_group_count = 2;
  m.rg_cycles[0] = 1000 + k;
  m.rg_max_exec_ns[1] = 123456789;
  m.cmd_rejected = k;
  m.uplink_id = -1;
  return m;
}

rocksteady::plant_truth_t truth(int k) {
  auto m = wire::make<rocksteady::plant_truth_t>();
  m.seq = k;
  m.t = 0.1 * k;
  m.quat[3] = 1.0;
  m.omega[2] = 0.05 * (k + 1);
  m.omega_norm = 0.05 * (k + 1);
  m.fuel_used_kg = 0.25 * k;
  return m;
}

class Log2Csv : public ::testing::Test {
 protected:
  void SetUp() override {
    log_ = dir_.file("run.lcmlog");
    lcm::LogFile log(log_, "w");
    ASSERT_TRUE(log.good());
    std::int64_t utime = 1700000000000000;
    auto write = [&](const char* channel, std::vector<unsigned char> data) {
      lcm::LogEvent ev{};
      ev.timestamp = utime;
      utime += 100000;
      ev.channel = channel;
      ev.datalen = static_cast<std::int32_t>(data.size());
      ev.data = data.data();
      ASSERT_EQ(log.writeEvent(&ev), 0);
    };
    for (int k = 0; k < 3; ++k) {
      write(channels::kGncTelemetry, bytes(telemetry(k)));
      write(channels::kPlantTruth, bytes(truth(k)));
    }
    // Garbage on the telemetry channel: random bytes, a truth message, a truncated telemetry.
    std::vector<unsigned char> noise(700);
    unsigned state = 12345;
    for (unsigned char& b : noise) {
      state = state * 1103515245u + 12345u;
      b = static_cast<unsigned char>(state >> 16);
    }
    write(channels::kGncTelemetry, noise);
    write(channels::kGncTelemetry, bytes(truth(9)));
    std::vector<unsigned char> cut = bytes(telemetry(5));
    cut.resize(100);
    write(channels::kGncTelemetry, cut);
    auto e = wire::make<rocksteady::event_t>();
    e.t = 2.5;
    e.seq = 4;
    e.severity = rocksteady::event_t::SEV_WARNING;
    e.id = 101;
    e.arg0 = 2;
    e.arg1 = 7;
    e.text = "SET_TARGET (2) seq 5 rejected: \"not allowed\", in TRACK";
    write(channels::kEvents, bytes(e));
  }

  test::TempDir dir_;
  std::string log_;
};

TEST_F(Log2Csv, TelemetryHeaderIsTheLcmFieldsAndValuesRoundTrip) {
  std::ostringstream out;
  const Log2CsvStats st = log2csv(log_, channels::kGncTelemetry, out);
  EXPECT_EQ(st.events, 10u);
  EXPECT_EQ(st.on_channel, 6u);
  EXPECT_EQ(st.written, 3u);
  EXPECT_EQ(st.rejected(), 3u);
  EXPECT_EQ(st.rx.bad_fingerprint, 2u);
  EXPECT_EQ(st.rx.too_short, 1u);

  const auto rows = parse_csv(out.str());
  ASSERT_EQ(rows.size(), 4u);
  std::vector<std::string> expected{"log_utime"};
  for (const std::string& f : lcm_fields("gnc_telemetry_t")) expected.push_back(f);
  expect_fields_then_names(rows[0], expected);
  const auto& h = rows[0];
  for (int k = 0; k < 3; ++k) {
    const auto& r = rows[static_cast<std::size_t>(k + 1)];
    ASSERT_EQ(r.size(), h.size());
    const auto m = telemetry(k);
    EXPECT_EQ(std::stoll(r[column(h, "log_utime")]), 1700000000000000 + 2 * k * 100000);
    EXPECT_EQ(std::strtod(r[column(h, "t")].c_str(), nullptr), m.t);  // exact
    EXPECT_EQ(std::stoll(r[column(h, "tick")]), m.tick);
    EXPECT_EQ(std::stoi(r[column(h, "mode")]), 2);
    EXPECT_EQ(std::stoi(r[column(h, "law")]), k);
    // The dictionary's names beside the numbers.
    EXPECT_EQ(r[column(h, "mode_name")], "HOLD");
    EXPECT_EQ(r[column(h, "law_name")], law_name(k));
    EXPECT_EQ(std::strtod(r[column(h, "omega_hat_1")].c_str(), nullptr), m.omega_hat[1]);
    EXPECT_EQ(std::strtod(r[column(h, "omega_hat_0")].c_str(), nullptr), 0.0);
    EXPECT_EQ(std::strtod(r[column(h, "fuel_kg")].c_str(), nullptr), m.fuel_kg);
    EXPECT_EQ(std::stoll(r[column(h, "rg_cycles_0")]), 1000 + k);
    EXPECT_EQ(std::stoll(r[column(h, "rg_max_exec_ns_1")]), 123456789);
    EXPECT_EQ(std::stoll(r[column(h, "cmd_rejected")]), k);
    EXPECT_EQ(std::stoi(r[column(h, "uplink_id")]), -1);
  }
}

TEST_F(Log2Csv, TruthChannelConvertsWithoutRejections) {
  std::ostringstream out;
  const Log2CsvStats st = log2csv(log_, channels::kPlantTruth, out);
  EXPECT_EQ(st.on_channel, 3u);
  EXPECT_EQ(st.written, 3u);
  EXPECT_EQ(st.rejected(), 0u);
  const auto rows = parse_csv(out.str());
  ASSERT_EQ(rows.size(), 4u);
  std::vector<std::string> expected{"log_utime"};
  for (const std::string& f : lcm_fields("plant_truth_t")) expected.push_back(f);
  EXPECT_EQ(rows[0], expected);
  for (int k = 0; k < 3; ++k) {
    const auto& r = rows[static_cast<std::size_t>(k + 1)];
    EXPECT_EQ(std::stoll(r[column(rows[0], "seq")]), k);
    EXPECT_EQ(std::strtod(r[column(rows[0], "omega_2")].c_str(), nullptr), truth(k).omega[2]);
    EXPECT_EQ(std::strtod(r[column(rows[0], "quat_3")].c_str(), nullptr), 1.0);
    EXPECT_EQ(std::strtod(r[column(rows[0], "fuel_used_kg")].c_str(), nullptr), 0.25 * k);
  }
}

TEST_F(Log2Csv, EventTextWithCommasAndQuotesSurvives) {
  std::ostringstream out;
  const Log2CsvStats st = log2csv(log_, channels::kEvents, out);
  EXPECT_EQ(st.written, 1u);
  const auto rows = parse_csv(out.str());
  ASSERT_EQ(rows.size(), 2u);
  ASSERT_EQ(rows[1].size(), rows[0].size());
  EXPECT_EQ(rows[1][column(rows[0], "text")],
            "SET_TARGET (2) seq 5 rejected: \"not allowed\", in TRACK");
  EXPECT_EQ(rows[1][column(rows[0], "id")], "101");
  EXPECT_EQ(rows[1][column(rows[0], "severity")], "2");
  EXPECT_EQ(rows[1][column(rows[0], "id_name")], fsw::to_string(fsw::EventId::kCommandRejected));
  EXPECT_EQ(rows[1][column(rows[0], "severity_name")], "WARNING");
}

TEST(CsvHeaders, EverySupportedChannelHasItsLcmFields) {
  const std::vector<std::pair<std::string, std::string>> channel_types{
      {channels::kGncTelemetry, "gnc_telemetry_t"},
      {channels::kPlantTruth, "plant_truth_t"},
      {channels::kSensors, "sensor_frame_t"},
      {channels::kThrusterCmd, "thruster_cmd_t"},
      {channels::kEvents, "event_t"},
      {channels::kCmdAck, "cmd_ack_t"},
      {channels::kGroundCmd, "ground_cmd_t"},
      {channels::kTrajUplink, "trajectory_chunk_t"},
  };
  for (const auto& [channel, type] : channel_types) {
    EXPECT_TRUE(csv_supported(channel)) << channel;
    std::vector<std::string> expected{"log_utime"};
    for (const std::string& f : lcm_fields(type)) expected.push_back(f);
    EXPECT_GT(expected.size(), 4u) << type;
    expect_fields_then_names(csv_header(channel), expected);
  }
  EXPECT_FALSE(csv_supported("RS_NOT_A_CHANNEL"));
}

TEST(CsvHeaders, UnsupportedChannelOrMissingLogIsAnError) {
  std::ostringstream out;
  EXPECT_THROW(log2csv("/nonexistent/run.lcmlog", channels::kGncTelemetry, out),
               std::runtime_error);
  test::TempDir dir;
  { lcm::LogFile(dir.file("empty.lcmlog"), "w"); }
  EXPECT_THROW(log2csv(dir.file("empty.lcmlog"), "RS_NOT_A_CHANNEL", out), std::runtime_error);
}

TEST(CsvLine, QuotesOnlyWhereNeeded) {
  EXPECT_EQ(csv_line({"a", "1.5", ""}), "a,1.5,\n");
  EXPECT_EQ(csv_line({"x,y", "say \"hi\""}), "\"x,y\",\"say \"\"hi\"\"\"\n");
}

TEST_F(Log2Csv, CommandLineWritesTheFileAndReportsRejections) {
  const std::string csv = dir_.file("tlm.csv");
  const test::Run r =
      test::run(std::string(ROCKSTEADY_GROUND_EXE) + " log2csv " + test::quote(log_) +
                    " --channel RS_GNC_TLM -o " + test::quote(csv),
                dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("3 rows; 3 rejected: 1 too short, 2 bad fingerprint"), std::string::npos)
      << r.err;
  EXPECT_EQ(parse_csv(test::read_file(csv)).size(), 4u);

  const test::Run strict =
      test::run(std::string(ROCKSTEADY_GROUND_EXE) + " log2csv " + test::quote(log_) +
                    " --channel RS_GNC_TLM --strict -o " + test::quote(csv),
                dir_);
  EXPECT_EQ(strict.exit_code, 1);

  const test::Run bad = test::run(
      std::string(ROCKSTEADY_GROUND_EXE) + " log2csv " + test::quote(log_) + " --channel RS_NOPE",
      dir_);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("not supported"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace rocksteady::ground::cli
