// Fixed-rate executive: rate groups scheduled by dividers of a base tick, with per-group cycle
// count, last/max execution time, slips and missed ticks (F Prime's ActiveRateGroup habits).
//
// A slip: a group's tick became due (Tick::start_ns) before that group's previous cycle had
// ended. A missed tick: a base tick the source skipped (late wake-up, sensor-frame gap); a group
// misses the cycles that fell on skipped base ticks. Slips raise a throttled warning: at most one
// report per interval, carrying the number of reports suppressed since the previous one.
#pragma once

#include <array>
#include <cstdint>

#include "fsw/executive/tick_source.hpp"
#include "fsw/interface.hpp"
#include "gnc/check.hpp"

namespace rocksteady::fsw {

struct ExecutiveConfig {
  double base_rate_hz{10.0};
  std::uint32_t gnc_divider{1};            // GNC at base / gnc_divider (10 Hz by default)
  std::uint32_t housekeeping_divider{10};  // housekeeping at base / divider (1 Hz by default)
  double slip_event_interval_s{10.0};      // throttle of the slip / missed-tick warnings
};

using ConfigCheck = gnc::Check;  // the one {ok, field, reason} result (gnc/check.hpp)
ConfigCheck validate(const ExecutiveConfig& c);

// The executive of a lockstep run: base tick = GNC tick = one sensor frame every `gnc_dt` seconds,
// housekeeping every `housekeeping_period_s` (rounded to whole ticks, at least one).
ExecutiveConfig lockstep_executive(double gnc_dt, double housekeeping_period_s = 1.0);

enum class GroupId : std::uint8_t { kGnc = 0, kHousekeeping = 1 };
inline constexpr int kGroupCount = 2;
const char* to_string(GroupId g);

// At most one report per interval; counts what it suppressed in between.
class Throttle {
 public:
  void configure(std::int64_t interval_ns) { interval_ns_ = interval_ns; }
  // True when a report may go out now; `suppressed` = reports held back since the last one.
  bool allow(std::int64_t now_ns, std::uint32_t& suppressed);
  void reset() {
    fired_ = false;
    suppressed_ = 0;
  }

 private:
  std::int64_t interval_ns_{0};
  std::int64_t last_ns_{0};
  bool fired_{false};
  std::uint32_t suppressed_{0};
};

struct SlipReport {
  bool slipped{false};
  bool report{false};           // emit the (throttled) warning event now
  std::uint32_t suppressed{0};  // slip reports suppressed since the previous warning
  std::int64_t late_ns{0};      // how far the previous cycle ran past this tick's start
};

class RateGroup {
 public:
  void configure(std::uint32_t divider, std::int64_t event_interval_ns);
  std::uint32_t divider() const { return divider_; }
  bool due(std::uint64_t index) const { return index % divider_ == 0; }
  // Cycles of this group on base ticks strictly between `from` and `to`.
  std::uint32_t cycles_between(std::uint64_t from, std::uint64_t to) const;

  // Start of a cycle for a tick due at `tick_start_ns`; slip detection against the previous end.
  SlipReport begin(std::int64_t tick_start_ns, std::int64_t now_ns);
  void end(std::int64_t now_ns);
  void add_missed(std::uint32_t n) { stats_.missed_ticks += n; }

  const RateGroupStats& stats() const { return stats_; }
  void reset_counters();  // slips, missed, max time (not the cycle count)

 private:
  std::uint32_t divider_{1};
  RateGroupStats stats_{};
  std::int64_t begin_ns_{0};
  std::int64_t last_end_ns_{0};
  bool ran_{false};
  Throttle slip_throttle_{};
};

struct TickPlan {
  bool valid{false};  // false: tick index not after the last one
  std::array<bool, kGroupCount> due{};
  std::array<std::uint32_t, kGroupCount> missed{};  // cycles of each group skipped before it
  std::uint32_t base_missed{0};
};

class Executive {
 public:
  ConfigCheck configure(const ExecutiveConfig& c);
  const ExecutiveConfig& config() const { return config_; }

  // Account one base tick: which groups run, how many cycles each missed (added to its stats).
  TickPlan plan(const Tick& tick);

  RateGroup& group(GroupId g) { return groups_[static_cast<int>(g)]; }
  const RateGroup& group(GroupId g) const { return groups_[static_cast<int>(g)]; }

  std::int64_t base_period_ns() const { return base_period_ns_; }
  double gnc_period_s() const;
  std::uint64_t base_ticks() const { return base_ticks_; }
  std::uint32_t base_missed() const { return base_missed_; }
  std::uint32_t out_of_order_ticks() const { return out_of_order_; }
  void reset_counters();

 private:
  ExecutiveConfig config_{};
  std::int64_t base_period_ns_{100000000};
  std::array<RateGroup, kGroupCount> groups_{};
  bool have_tick_{false};
  std::uint64_t last_index_{0};
  std::uint64_t base_ticks_{0};
  std::uint32_t base_missed_{0};
  std::uint32_t out_of_order_{0};
};

}  // namespace rocksteady::fsw
