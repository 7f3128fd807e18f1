#include "fsw/events/event_translator.hpp"

#include <array>
#include <cstdio>

namespace rocksteady::fsw {

namespace {

// How a row fills arg0/arg1 and the text's third field.
enum class Args : std::uint8_t {
  kFromTo,           // arg0 = from, arg1 = to
  kToReason,         // arg0 = requested mode, arg1 = gnc::TransitionCheck
  kRejectsThrottled,  // arg0 = rejects so far, arg1 = suppressed reports; throttled
  kData               // arg0, arg1 = the event's own data (fault events)
};
enum class Detail : std::uint8_t { kNone, kCause, kTimeout, kReason, kRejects, kArgs };

struct Row {
  gnc::EventId gnc_id;
  EventId id;
  Severity severity;
  Args args;
  Detail detail;
  const char* text;  // printf with %s: from, to, detail (in that order; each may be unused)
};

constexpr std::array<Row, 17> kRows{{
    {gnc::EventId::kModeChanged, EventId::kModeChanged, Severity::kInfo, Args::kFromTo,
     Detail::kCause, "mode %s -> %s (%s)"},
    {gnc::EventId::kAutoHold, EventId::kAutoHold, Severity::kInfo, Args::kFromTo, Detail::kNone,
     "mode %s -> %s: |omega| <= omega_switch%s"},
    {gnc::EventId::kSensorTimeout, EventId::kSensorTimeout, Severity::kError, Args::kFromTo,
     Detail::kTimeout, "mode %s -> %.0sSAFE: no valid sensor sample for %s s, thrusters off"},
    {gnc::EventId::kNonFiniteState, EventId::kNonFiniteState, Severity::kError, Args::kFromTo,
     Detail::kNone, "mode %s -> %.0sSAFE: non-finite estimate or command, thrusters off%s"},
    {gnc::EventId::kRequestRejected, EventId::kModeRequestRejected, Severity::kWarning,
     Args::kToReason, Detail::kReason, "mode request %.0s%s rejected at the tick: %s"},
    {gnc::EventId::kSensorRejected, EventId::kSensorRejected, Severity::kWarning,
     Args::kRejectsThrottled, Detail::kRejects,
     "sensor sample rejected: invalid, non-finite or out of range (%.0s%.0s%s so far)"},
    {gnc::EventId::kModelAdopted, EventId::kModelAdopted, Severity::kInfo, Args::kFromTo,
     Detail::kNone, "identified model (J_tot, r_SO/BCM, strengths) adopted in %.0s%s%s"},
    {gnc::EventId::kModelRefused, EventId::kModelRefused, Severity::kWarning, Args::kFromTo,
     Detail::kNone, "identified model refused: fails table validation (in %.0s%s%s)"},
    {gnc::EventId::kFaultSuspected, EventId::kFaultSuspected, Severity::kWarning, Args::kData,
     Detail::kArgs, "thruster fault suspected in %.0s%s: residual above the no-fault bound (%s)"},
    {gnc::EventId::kFaultConfirmed, EventId::kFaultConfirmed, Severity::kError, Args::kData,
     Detail::kArgs, "thruster fault confirmed in %.0s%s, latched until the ground clears it (%s)"},
    {gnc::EventId::kValveClosed, EventId::kValveClosed, Severity::kWarning, Args::kData,
     Detail::kArgs, "latch valve closed in %.0s%s to isolate a stuck-on thruster (%s)"},
    {gnc::EventId::kFaultOverride, EventId::kFaultOverride, Severity::kInfo, Args::kData,
     Detail::kArgs, "fault management override applied in %.0s%s (%s)"},
    {gnc::EventId::kReducedAuthority, EventId::kReducedAuthority, Severity::kWarning, Args::kData,
     Detail::kArgs, "reduced control authority in %.0s%s: some torque directions unreachable (%s)"},
    {gnc::EventId::kTrajectorySwitched, EventId::kTrajectorySwitched, Severity::kInfo,
     Args::kFromTo, Detail::kNone,
     "trajectory switched at the tick boundary (mode %s%.0s): reference re-synchronised%s"},
    {gnc::EventId::kTrajectoryStale, EventId::kTrajectoryStale, Severity::kWarning,
     Args::kFromTo, Detail::kNone,
     "staged trajectory refused at the tick boundary (mode %s%.0s): stale, active one kept%s"},
    {gnc::EventId::kIsolationTest, EventId::kIsolationTest, Severity::kWarning, Args::kData,
     Detail::kArgs, "isolation test in %.0s%s: a pod's latch valve closed or reopened (%s)"},
    {gnc::EventId::kJetCheck, EventId::kJetCheck, Severity::kInfo, Args::kData, Detail::kArgs,
     "jet check in %.0s%s: a suspected thruster fired torque-free, or its check ended (%s)"},
}};

const Row* find_row(gnc::EventId id) {
  for (const Row& r : kRows) {
    if (r.gnc_id == id) return &r;
  }
  return nullptr;
}

}  // namespace

void EventTranslator::configure(std::int64_t sensor_event_interval_ns) {
  sensor_throttle_.configure(sensor_event_interval_ns);
  sensor_throttle_.reset();
}

void EventTranslator::translate(const gnc::ModeEvents& events, const TranslationContext& ctx,
                                EventLog& log) {
  for (int i = 0; i < events.count; ++i) {
    const gnc::ModeEvent& e = events.items[i];
    const Row* row = find_row(e.id);
    if (row == nullptr) continue;
    auto arg0 = static_cast<std::int32_t>(e.from);
    auto arg1 = static_cast<std::int32_t>(e.to);
    if (row->args == Args::kToReason) {
      arg0 = static_cast<std::int32_t>(e.to);
      arg1 = static_cast<std::int32_t>(e.reason);
    } else if (row->args == Args::kData) {
      arg0 = e.arg0;
      arg1 = e.arg1;
    } else if (row->args == Args::kRejectsThrottled) {
      std::uint32_t suppressed = 0;
      if (!sensor_throttle_.allow(ctx.now_ns, suppressed)) continue;
      arg0 = static_cast<std::int32_t>(ctx.sensor_rejects);
      arg1 = static_cast<std::int32_t>(suppressed);
    }
    char detail[32] = "";
    switch (row->detail) {
      case Detail::kNone:
        break;
      case Detail::kCause:
        std::snprintf(detail, sizeof detail, "%s",
                      ctx.overrun_request ? "overrun protection" : "ground request");
        break;
      case Detail::kTimeout:
        std::snprintf(detail, sizeof detail, "%.3g", ctx.sensor_timeout_s);
        break;
      case Detail::kReason:
        std::snprintf(detail, sizeof detail, "%s", gnc::to_string(e.reason));
        break;
      case Detail::kRejects:
        std::snprintf(detail, sizeof detail, "%u", ctx.sensor_rejects);
        break;
      case Detail::kArgs:
        std::snprintf(detail, sizeof detail, "%d, %d", static_cast<int>(e.arg0),
                      static_cast<int>(e.arg1));
        break;
    }
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
    log.emit(row->severity, row->id, arg0, arg1, row->text, gnc::to_string(e.from),
             gnc::to_string(e.to), detail);
#pragma GCC diagnostic pop
  }
}

}  // namespace rocksteady::fsw
