// rocksteady-ground plot: a PIL-style LCM log and a campaign CSV written here are read back (truth,
// estimate, reference), the SPEC §7 convergence times match the closed form of the data, and the
// PNG is drawn by gnuplot at the requested size with the NC annotation where a criterion is never
// met.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <lcm/lcm-cpp.hpp>

#include "ground/cli/plot.hpp"
#include "wire/codec.hpp"
#include "test_util.hpp"

namespace rocksteady::ground::cli {
namespace {

constexpr double kTau = 100.0;  // omega(t) = 0.01 exp(-t / tau) on x
constexpr double kStep = 10.0;  // one sample per 10 s
constexpr int kSamples = 101;   // t = 0 .. 1000 s

double omega_x(double t) {
  return 0.01 * std::exp(-t / kTau);
}

template <class T>
void write_event(lcm::LogFile& log, const char* channel, const T& m, std::int64_t utime) {
  std::vector<unsigned char> buf(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  lcm::LogEvent ev{};
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = static_cast<std::int32_t>(buf.size());
  ev.data = buf.data();
  ASSERT_EQ(log.writeEvent(&ev), 0);
}

std::string write_log(const test::TempDir& dir) {
  const std::string path = dir.file("run.lcmlog");
  lcm::LogFile log(path, "w");
  EXPECT_TRUE(log.good());
  for (int k = 0; k < kSamples; ++k) {
    const double t = kStep * k;
    auto truth = wire::make<rocksteady::plant_truth_t>();
    truth.seq = k;
    truth.t = t;
    truth.quat[3] = 1.0;
    truth.q[0] = 0.5;  // never near q_final = 0: t_q is NC
    truth.omega[0] = omega_x(t);
    truth.omega_norm = omega_x(t);
    truth.fuel_used_kg = 0.1 * k;
    write_event(log, "RS_PLANT_TRUTH", truth, 1000000 * k);
    auto tlm = wire::make<rocksteady::gnc_telemetry_t>();
    tlm.t = t;
    tlm.tick = k;
    tlm.mode = 1;
    tlm.omega_hat[0] = omega_x(t) + 1e-6;
    tlm.omega_r[0] = 0.5 * omega_x(t);
    tlm.q_hat[0] = 0.5;
    tlm.attitude_error[0] = 0.5;  // q_final = q_hat - error = 0
    tlm.alloc_scale = 1.0;
    tlm.uplink_id = -1;
    tlm.rate_group_count = 2;
    tlm.fuel_kg = 0.1 * k + 0.01;
    write_event(log, "RS_GNC_TLM", tlm, 1000000 * k + 1);
  }
  return path;
}

TEST(Plot, ReadsAPilLogAndFindsConvergenceAsTheClosedFormSays) {
  test::TempDir dir;
  const PlotData d = load_plot_data(write_log(dir));
  ASSERT_EQ(d.omega.size(), static_cast<std::size_t>(kSamples));
  ASSERT_EQ(d.omega_hat.size(), static_cast<std::size_t>(kSamples));
  ASSERT_EQ(d.omega_r.size(), static_cast<std::size_t>(kSamples));
  ASSERT_EQ(d.fuel_hat.size(), static_cast<std::size_t>(kSamples));
  EXPECT_EQ(d.omega[7].value[0], omega_x(70.0));
  EXPECT_EQ(d.omega_r[7].value[0], 0.5 * omega_x(70.0));
  ASSERT_TRUE(d.q_final.has_value());
  EXPECT_EQ((*d.q_final)[0], 0.0);
  // |omega| <= 1e-4 from t = tau ln(100) = 460.5 s on: the first sample after it is t = 470 s.
  const Convergence c = convergence(d, {0.0, 0.0, 0.0});
  ASSERT_TRUE(c.t_omega.has_value());
  EXPECT_EQ(*c.t_omega, kStep * std::ceil(kTau * std::log(100.0) / kStep));
  EXPECT_FALSE(c.t_q.has_value());
  // Against a target the attitude does reach, t_q is the first sample.
  EXPECT_EQ(convergence(d, {0.5, 0.0, 0.0}).t_q, 0.0);
}

TEST(Plot, DrawsThePngAtItsSizeWithMarksAndNc) {
  test::TempDir dir;
  const PlotData d = load_plot_data(write_log(dir));
  PlotOptions o;
  o.output = dir.file("fig3.png");
  ASSERT_EQ(write_plot(d, o), "");
  std::ifstream png(o.output, std::ios::binary);
  unsigned char h[24] = {};
  png.read(reinterpret_cast<char*>(h), 24);
  ASSERT_EQ(png.gcount(), 24);
  EXPECT_EQ(std::string(reinterpret_cast<char*>(h) + 1, 3), "PNG");
  const auto be32 = [&](int at) {
    return (h[at] << 24) | (h[at + 1] << 16) | (h[at + 2] << 8) | h[at + 3];
  };
  EXPECT_EQ(be32(16), o.width);
  EXPECT_EQ(be32(20), o.height);
  const std::string gp = test::read_file(dir.file("fig3.gp"));
  EXPECT_NE(gp.find("t_omega,conv = 470 s"), std::string::npos) << gp;
  EXPECT_NE(gp.find("t_q,conv: NC"), std::string::npos) << gp;
  // Truth, estimate and reference are told apart by dash type.
  EXPECT_NE(gp.find("dt 1 lw 2 title 'omega_x true'"), std::string::npos) << gp;
  EXPECT_NE(gp.find("dt 2 lw 1 title 'omega_x estimate'"), std::string::npos) << gp;
  EXPECT_NE(gp.find("dt 3 lw 1 title 'omega_x reference'"), std::string::npos) << gp;
}

TEST(Plot, ReadsACampaignCsvAndNamesABadCell) {
  test::TempDir dir;
  const std::string path = dir.file("timeseries.csv");
  {
    std::ofstream out(path);
    out << "t_s,omega_x,omega_y,omega_z,omega_hat_x,omega_hat_y,omega_hat_z,q_x,q_y,q_z,"
           "q_hat_x,q_hat_y,q_hat_z,fuel_kg,fuel_hat_kg,mode\n";
    for (int k = 0; k < 5; ++k) {
      out << 10 * k << "," << omega_x(10.0 * k) << ",0,0,0,0,0,0.1,0,0,0.1,0,0," << k << ","
          << k + 0.5 << ",HOLD\n";
    }
  }
  const PlotData d = load_plot_data(path);
  EXPECT_EQ(d.omega.size(), 5u);
  EXPECT_EQ(d.omega_hat.size(), 5u);
  EXPECT_EQ(d.fuel_hat.size(), 5u);
  EXPECT_EQ(d.fuel_hat[3].second, 3.5);
  EXPECT_TRUE(d.omega_r.empty());
  {
    std::ofstream out(path, std::ios::app);
    out << "50,fast,0,0,0,0,0,0.1,0,0,0.1,0,0,5,5.5,HOLD\n";
  }
  try {
    load_plot_data(path);
    FAIL() << "a non-numeric cell was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("timeseries.csv:7: column omega_x is not a number"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace rocksteady::ground::cli
