// Verification cost per command (fsw/auth): the HMAC of one ground command and one uplink chunk,
// verify() with its replay window, and a whole authenticated FlightApp::submit (NOOP) next to an
// unauthenticated lab-mode one, so the difference is the price of authentication. Prints; never
// asserts a time.
#include <benchmark/benchmark.h>

#include <cstring>
#include <memory>

#include "fsw/app/flight_app.hpp"
#include "fsw/auth/auth.hpp"
#include "gnc/params.hpp"

namespace {

using namespace rocksteady::fsw;

auth::Key test_key() {
  auth::Key k;
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<std::uint8_t>(3 * i + 1);
  return k;
}

GroundCommand command(std::int64_t counter, const auth::Key& key) {
  GroundCommand c;
  c.seq = counter;
  c.source = 1;
  c.opcode = static_cast<std::int32_t>(Opcode::kNoop);
  c.key_id = 1;
  auth::MacBytes m;
  auth::mac_command(c, key, m);
  std::memcpy(c.mac.data(), m.data(), m.size());
  return c;
}

void BM_MacCommand(benchmark::State& state) {
  const auth::Key key = test_key();
  GroundCommand c = command(1, key);
  auth::MacBytes m;
  for (auto _ : state) {
    auth::mac_command(c, key, m);
    benchmark::DoNotOptimize(m);
    ++c.seq;
  }
}
BENCHMARK(BM_MacCommand);

void BM_MacChunk(benchmark::State& state) {
  const auth::Key key = test_key();
  TrajectoryChunk ch;
  ch.n = 32;
  ch.total_samples = 1024;
  ch.chunk_count = 32;
  auth::MacBytes m;
  for (auto _ : state) {
    auth::mac_chunk(ch, key, m);
    benchmark::DoNotOptimize(m);
    ++ch.seq;
  }
}
BENCHMARK(BM_MacChunk);

// verify(): MAC + constant-time compare + replay window (a full window of 64 counters).
void BM_VerifyCommand(benchmark::State& state) {
  const auth::Key key = test_key();
  auth::SecurityConfig cfg;
  cfg.keys.count = 1;
  cfg.keys.keys[0] = {1, key};
  auth::CommandSecurity sec;
  if (!sec.init(cfg).ok) state.SkipWithError("init");
  std::int64_t counter = 1;
  // Pre-sign a batch outside the timing (signing is the ground's cost).
  constexpr int kBatch = 4096;
  auto batch = std::make_unique<GroundCommand[]>(kBatch);
  int i = kBatch;
  for (auto _ : state) {
    if (i == kBatch) {
      state.PauseTiming();
      for (int k = 0; k < kBatch; ++k) batch[k] = command(counter++, key);
      i = 0;
      state.ResumeTiming();
    }
    benchmark::DoNotOptimize(sec.verify(batch[i++]));
  }
}
BENCHMARK(BM_VerifyCommand);

// A forged command costs the same MAC (constant-time compare), and changes nothing.
void BM_RejectForgedCommand(benchmark::State& state) {
  const auth::Key key = test_key();
  auth::SecurityConfig cfg;
  cfg.keys.count = 1;
  cfg.keys.keys[0] = {1, key};
  auth::CommandSecurity sec;
  if (!sec.init(cfg).ok) state.SkipWithError("init");
  GroundCommand forged = command(5, key);
  forged.mac[3] ^= 1;
  for (auto _ : state) benchmark::DoNotOptimize(sec.verify(forged));
}
BENCHMARK(BM_RejectForgedCommand);

class BenchClock final : public Clock {
 public:
  std::int64_t now_ns() const override { return t_ += 1000; }
  void sleep_until(std::int64_t) override {}

 private:
  mutable std::int64_t t_{0};
};

// A whole submission (authenticate, check, execute, acknowledge, event) through the flight
// application, with keys and in lab mode.
void BM_SubmitNoop(benchmark::State& state, bool keyed) {
  static FlightApp app;  // large: static storage
  BenchClock clock;
  FlightConfig cfg;
  cfg.gnc = rocksteady::gnc::study_gnc_params(200.0);
  cfg.executive.base_rate_hz = 1.0 / cfg.gnc.dt;
  const auth::Key key = test_key();
  if (keyed) {
    cfg.security.keys.count = 1;
    cfg.security.keys.keys[0] = {1, key};
  } else {
    cfg.security.lab_mode = true;
  }
  if (!app.init(cfg, clock).ok) state.SkipWithError("init");
  constexpr int kBatch = 4096;
  auto batch = std::make_unique<GroundCommand[]>(kBatch);
  std::int64_t counter = 1;
  int i = kBatch;
  Event e;
  for (auto _ : state) {
    if (i == kBatch) {
      state.PauseTiming();
      for (int k = 0; k < kBatch; ++k) {
        batch[k] = keyed ? command(counter, key) : GroundCommand{};
        if (!keyed) {
          batch[k].seq = counter;
          batch[k].source = 1;
        }
        ++counter;
      }
      while (app.pop_event(e)) {
      }
      i = 0;
      state.ResumeTiming();
    }
    const CommandAck a = app.submit(batch[i++]);
    if (!a.accepted) state.SkipWithError("a valid command was refused");
    while (app.pop_event(e)) {
    }
  }
}
BENCHMARK_CAPTURE(BM_SubmitNoop, authenticated, true);
BENCHMARK_CAPTURE(BM_SubmitNoop, lab_mode, false);

}  // namespace

BENCHMARK_MAIN();
