// The console server's telemetry store: a bounded history with at most one sample per interval
// (the newest of each interval), the newest sample per channel for the real-time feed, events with
// the dictionary's names, and messages that fail the safe decode counted and left out.
#include <gtest/gtest.h>

#include <vector>

#include "ground/console/telemetry_store.hpp"

namespace rocksteady::ground::console {
namespace {

std::vector<unsigned char> encode_tlm(double t, double omega0) {
  auto m = wire::make<rocksteady::gnc_telemetry_t>();
  m.t = t;
  m.omega_hat[0] = omega0;
  m.alloc_scale = 1.0;
  m.uplink_id = -1;
  m.rate_group_count = 2;
  std::vector<unsigned char> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

TEST(TelemetryStore, KeepsTheNewestSampleOfEachIntervalAndFiltersByTime) {
  TelemetryStore::Options o;
  o.min_interval_ms = 50.0;
  TelemetryStore store(o);
  const dictionary::Channel* c = dictionary::find_channel("RS_GNC_TLM");
  const int w0 = dictionary::find_point(*c, "omega_hat_0");
  // Messages every 10 ms for 200 ms; omega_hat_0 = the arrival time, so a value names its message.
  for (int k = 0; k <= 20; ++k) {
    const double utc = 1000.0 + 10.0 * k;
    const auto b = encode_tlm(0.1 * k, utc);
    ASSERT_TRUE(store.add("RS_GNC_TLM", b.data(), static_cast<int>(b.size()), utc));
  }
  // Brute force: intervals start at the first message not within 50 ms of the previous start.
  std::vector<std::pair<double, double>> expected;
  double start = -1e9;
  for (int k = 0; k <= 20; ++k) {
    const double utc = 1000.0 + 10.0 * k;
    if (utc - start >= 50.0) {
      start = utc;
      expected.emplace_back(utc, utc);
    } else {
      expected.back() = {utc, utc};
    }
  }
  EXPECT_EQ(store.history("RS_GNC_TLM", w0, 0.0, 1e18), expected);
  // A window keeps only what falls in it.
  const auto window = store.history("RS_GNC_TLM", w0, 1100.0, 1150.0);
  for (const auto& [utc, v] : window) {
    EXPECT_GE(utc, 1100.0);
    EXPECT_LE(utc, 1150.0);
  }
  EXPECT_FALSE(window.empty());
  // The real-time feed: only the newest sample, and only if newer than asked.
  const auto newer = store.newer_than(1150.0);
  ASSERT_EQ(newer.count("RS_GNC_TLM"), 1u);
  EXPECT_EQ(newer.at("RS_GNC_TLM").values[static_cast<std::size_t>(w0)], 1200.0);
  EXPECT_TRUE(store.newer_than(1200.0).empty());
  EXPECT_EQ(store.stats().at("RS_GNC_TLM").received, 21u);
}

TEST(TelemetryStore, CountsAndDropsWhatDoesNotDecode) {
  TelemetryStore store;
  auto b = encode_tlm(1.0, 0.5);
  EXPECT_FALSE(store.add("RS_GNC_TLM", b.data(), static_cast<int>(b.size()) - 3, 1.0));
  b[0] ^= 0xff;  // another fingerprint
  EXPECT_FALSE(store.add("RS_GNC_TLM", b.data(), static_cast<int>(b.size()), 2.0));
  EXPECT_FALSE(store.add("RS_NOT_A_CHANNEL", b.data(), static_cast<int>(b.size()), 3.0));
  EXPECT_EQ(store.stats().at("RS_GNC_TLM").rejected, 2u);
  EXPECT_EQ(store.stats().at("RS_GNC_TLM").received, 0u);
  EXPECT_TRUE(store.latest("RS_GNC_TLM").values.empty());
}

TEST(TelemetryStore, EventsCarryTheDictionarysNames) {
  TelemetryStore store;
  auto e = wire::make<rocksteady::event_t>();
  e.t = 17.0;
  e.severity = rocksteady::event_t::SEV_ERROR;
  e.id = 104;
  e.arg0 = 2;
  e.arg1 = 4;
  e.text = "mode HOLD -> SAFE";
  std::vector<unsigned char> b(static_cast<std::size_t>(e.getEncodedSize()));
  e.encode(b.data(), 0, static_cast<int>(b.size()));
  ASSERT_TRUE(store.add("RS_EVENTS", b.data(), static_cast<int>(b.size()), 5.0));
  e.id = 4242;
  e.severity = rocksteady::event_t::SEV_INFO;
  b.assign(static_cast<std::size_t>(e.getEncodedSize()), 0);
  e.encode(b.data(), 0, static_cast<int>(b.size()));
  ASSERT_TRUE(store.add("RS_EVENTS", b.data(), static_cast<int>(b.size()), 6.0));
  const auto events = store.events_after(0);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].name, "sensor_timeout");
  EXPECT_EQ(events[0].severity_name, "ERROR");
  EXPECT_EQ(events[0].t, 17.0);
  EXPECT_EQ(events[0].arg1, 4);
  EXPECT_EQ(events[0].text, "mode HOLD -> SAFE");
  EXPECT_EQ(events[1].name, "event 4242");  // unknown ids are shown as numbers
  EXPECT_EQ(store.events_after(events[0].index).size(), 1u);
}

}  // namespace
}  // namespace rocksteady::ground::console
