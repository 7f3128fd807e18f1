#include "fsw/executive/executive.hpp"

#include <cmath>

#include "gnc/units.hpp"

namespace rocksteady::fsw {

ConfigCheck validate(const ExecutiveConfig& c) {
  if (!std::isfinite(c.base_rate_hz) || c.base_rate_hz <= 0.0 || c.base_rate_hz > 10000.0) {
    return ConfigCheck{false, "executive.base_rate_hz", "must be in (0, 10000] Hz"};
  }
  if (c.gnc_divider < 1 || c.gnc_divider > 10000) {
    return ConfigCheck{false, "executive.gnc_divider", "must be in [1, 10000]"};
  }
  if (c.housekeeping_divider < 1 || c.housekeeping_divider > 100000) {
    return ConfigCheck{false, "executive.housekeeping_divider", "must be in [1, 100000]"};
  }
  if (!std::isfinite(c.slip_event_interval_s) || c.slip_event_interval_s < 0.0) {
    return ConfigCheck{false, "executive.slip_event_interval_s", "must be >= 0"};
  }
  return ConfigCheck{};
}

ExecutiveConfig lockstep_executive(double gnc_dt, double housekeeping_period_s) {
  ExecutiveConfig c;
  c.base_rate_hz = 1.0 / gnc_dt;
  c.gnc_divider = 1;
  const double ticks = std::round(housekeeping_period_s / gnc_dt);
  c.housekeeping_divider = std::isfinite(ticks) && ticks >= 1.0 && ticks <= 100000.0
                               ? static_cast<std::uint32_t>(ticks)
                               : 1;
  return c;
}

const char* to_string(GroupId g) {
  switch (g) {
    case GroupId::kGnc:
      return "gnc";
    case GroupId::kHousekeeping:
      return "housekeeping";
  }
  return "?";
}

bool Throttle::allow(std::int64_t now_ns, std::uint32_t& suppressed) {
  if (!fired_ || now_ns - last_ns_ >= interval_ns_) {
    fired_ = true;
    last_ns_ = now_ns;
    suppressed = suppressed_;
    suppressed_ = 0;
    return true;
  }
  ++suppressed_;
  suppressed = suppressed_;
  return false;
}

void RateGroup::configure(std::uint32_t divider, std::int64_t event_interval_ns) {
  divider_ = divider < 1 ? 1 : divider;
  slip_throttle_.configure(event_interval_ns);
}

std::uint32_t RateGroup::cycles_between(std::uint64_t from, std::uint64_t to) const {
  if (to <= from + 1) return 0;
  // Multiples of the divider in [from + 1, to - 1].
  const std::uint64_t upto = (to - 1) / divider_;
  const std::uint64_t below = from / divider_;
  const std::uint64_t n = upto - below;
  return n > 0xFFFFFFFFull ? 0xFFFFFFFFu : static_cast<std::uint32_t>(n);
}

SlipReport RateGroup::begin(std::int64_t tick_start_ns, std::int64_t now_ns) {
  SlipReport r;
  if (ran_ && last_end_ns_ > tick_start_ns) {  // the tick arrived before the last cycle ended
    r.slipped = true;
    r.late_ns = last_end_ns_ - tick_start_ns;
    ++stats_.slips;
    r.report = slip_throttle_.allow(now_ns, r.suppressed);
  }
  begin_ns_ = now_ns;
  return r;
}

void RateGroup::end(std::int64_t now_ns) {
  ++stats_.cycles;
  stats_.last_exec_ns = now_ns - begin_ns_;
  if (stats_.last_exec_ns > stats_.max_exec_ns) stats_.max_exec_ns = stats_.last_exec_ns;
  last_end_ns_ = now_ns;
  ran_ = true;
}

void RateGroup::reset_counters() {
  stats_.slips = 0;
  stats_.missed_ticks = 0;
  stats_.max_exec_ns = 0;
  slip_throttle_.reset();
}

ConfigCheck Executive::configure(const ExecutiveConfig& c) {
  const ConfigCheck check = validate(c);
  if (!check.ok) return check;
  config_ = c;
  const auto ns_per_s = static_cast<double>(gnc::kNsPerS);  // exactly 1e9
  base_period_ns_ = static_cast<std::int64_t>(std::llround(ns_per_s / c.base_rate_hz));
  const auto interval_ns =
      static_cast<std::int64_t>(std::llround(c.slip_event_interval_s * ns_per_s));
  group(GroupId::kGnc).configure(c.gnc_divider, interval_ns);
  group(GroupId::kHousekeeping).configure(c.housekeeping_divider, interval_ns);
  have_tick_ = false;
  last_index_ = 0;
  base_ticks_ = 0;
  base_missed_ = 0;
  out_of_order_ = 0;
  return check;
}

double Executive::gnc_period_s() const {
  return static_cast<double>(config_.gnc_divider) / config_.base_rate_hz;
}

TickPlan Executive::plan(const Tick& tick) {
  TickPlan p;
  if (have_tick_ && tick.index <= last_index_) {  // a source never does this; count, run nothing
    ++out_of_order_;
    return p;
  }
  p.valid = true;
  if (have_tick_) {
    // Saturating (a gap of 2^32 ticks must not wrap to a small number).
    const std::uint64_t gap = tick.index - last_index_ - 1;
    p.base_missed = gap > 0xFFFFFFFFull ? 0xFFFFFFFFu : static_cast<std::uint32_t>(gap);
    for (int g = 0; g < kGroupCount; ++g) {
      p.missed[g] = groups_[g].cycles_between(last_index_, tick.index);
      groups_[g].add_missed(p.missed[g]);
    }
  }
  for (int g = 0; g < kGroupCount; ++g) p.due[g] = groups_[g].due(tick.index);
  have_tick_ = true;
  last_index_ = tick.index;
  ++base_ticks_;
  base_missed_ = base_missed_ > 0xFFFFFFFFu - p.base_missed ? 0xFFFFFFFFu
                                                             : base_missed_ + p.base_missed;
  return p;
}

void Executive::reset_counters() {
  for (RateGroup& g : groups_) g.reset_counters();
  base_missed_ = 0;
  out_of_order_ = 0;
}

}  // namespace rocksteady::fsw
