// The parameter table's life cycle as the ground drives it (cFS-style): PARAM_LOAD writes one
// parameter into the inactive copy and validates the whole copy; PARAM_ACTIVATE stages a snapshot
// that becomes active at the next tick boundary (the law stays the commanded one); PARAM_DISCARD
// resets the inactive copy to the active table. Each step is answered, evented and counted.
#pragma once

#include <cstdint>

#include "fsw/commands/command_table.hpp"
#include "fsw/events/event_log.hpp"
#include "fsw/params/param_table.hpp"
#include "gnc/gnc.hpp"

namespace rocksteady::fsw {

class ParamLifecycle {
 public:
  void reset(const gnc::GncParams& active);

  CommandCheck load(const GroundCommand& cmd, EventLog& log);
  // PARAM_LOAD_IDENTIFIED: the core's identified model (J_tot, r_SO/BCM, confident strengths) into
  // the inactive table, validated like any load; the ground then activates it (PARAM_ACTIVATE).
  CommandCheck load_identified(const gnc::Gnc& core, EventLog& log);
  // May the inactive table be staged for the next boundary? Then stage it (the caller queues the
  // activation in between).
  CommandCheck check_stage() const;
  void stage() { table_.stage(); }
  CommandCheck discard(const gnc::GncParams& active, EventLog& log);
  // At the tick boundary: the staged table becomes the core's active table.
  void activate(gnc::Gnc& core, EventLog& log);
  // PARAM_DUMP: read the active table back now; the bus layer collects it with take_dump().
  CommandCheck dump(const gnc::GncParams& active, double t, EventLog& log);
  bool take_dump(ParamDump& out);

  const ParamTable& table() const { return table_; }
  std::uint32_t loads() const { return loads_; }
  std::uint32_t activations() const { return activations_; }

 private:
  ParamTable table_{};
  gnc::GncParams activation_{};  // scratch: too large for the stack of a tick
  std::uint32_t loads_{0};
  std::uint32_t activations_{0};
  ParamDump dump_{};
  bool dump_ready_{false};
};

}  // namespace rocksteady::fsw
