#include "fsw/params/param_lifecycle.hpp"

namespace rocksteady::fsw {

void ParamLifecycle::reset(const gnc::GncParams& active) {
  table_.reset(active);
  loads_ = 0;
  activations_ = 0;
  dump_ = ParamDump{};
  dump_ready_ = false;
}

CommandCheck ParamLifecycle::dump(const gnc::GncParams& active, double t, EventLog& log) {
  static_assert(kParamCount <= kMaxDumpParams, "the dump holds every parameter");
  const std::uint32_t seq = dump_.seq + 1;
  dump_ = ParamDump{};
  dump_.t = t;
  dump_.seq = seq;
  dump_.count = kParamCount;
  for (int i = 0; i < kParamCount; ++i) {
    const auto k = static_cast<std::size_t>(i);
    dump_.value_count[k] = read_param(active, i, dump_.values[k].data());
  }
  dump_ready_ = true;
  log.emit(Severity::kInfo, EventId::kParamsDumped, static_cast<std::int32_t>(seq), kParamCount,
           "active parameter table read back (%d parameters)", kParamCount);
  return CommandCheck{};
}

bool ParamLifecycle::take_dump(ParamDump& out) {
  if (!dump_ready_) return false;
  out = dump_;
  dump_ready_ = false;
  return true;
}

CommandCheck ParamLifecycle::load(const GroundCommand& cmd, EventLog& log) {
  const auto id = static_cast<std::int32_t>(cmd.args[0]);
  const ParamLoadResult r = table_.load(id, &cmd.args[1], cmd.arg_count - 1);
  if (!r.ok()) {
    if (r.reason == RejectReason::kInvalidTable) {
      log.emit(Severity::kWarning, EventId::kTableActivationFailed, id, 0,
               "parameter load %s rejected: %s %s", param_specs()[id].name, r.text, r.why);
    }
    return CommandCheck{r.reason, r.detail, r.text};
  }
  ++loads_;
  log.emit(Severity::kInfo, EventId::kTableLoaded, id, cmd.arg_count - 1,
           "parameter %s loaded into the inactive table", param_specs()[id].name);
  return CommandCheck{};
}

CommandCheck ParamLifecycle::load_identified(const gnc::Gnc& core, EventLog& log) {
  gnc::IdentifiedModel m;
  const gnc::ModelCandidate c = core.identified_model(m);
  if (c != gnc::ModelCandidate::kOk) {
    return CommandCheck{RejectReason::kInvalidTable, static_cast<std::int32_t>(c),
                        gnc::to_string(c)};
  }
  const ParamLoadResult r = table_.load_model(m.j, m.r, m.k);
  if (!r.ok()) {
    log.emit(Severity::kWarning, EventId::kModelRefused, 0, 0,
             "identified model refused: %s %s", r.text, r.why);
    return CommandCheck{r.reason, r.detail, r.text};
  }
  ++loads_;
  log.emit(Severity::kInfo, EventId::kModelLoaded, 0, 0,
           "identified model loaded into the inactive table (activate to fly it)");
  return CommandCheck{};
}

CommandCheck ParamLifecycle::check_stage() const {
  if (table_.staged())
    return CommandCheck{RejectReason::kBusy, 0, "an activation is already pending"};
  if (!table_.loaded())
    return CommandCheck{RejectReason::kNothingToActivate, 0, "no parameter load"};
  return CommandCheck{};
}

CommandCheck ParamLifecycle::discard(const gnc::GncParams& active, EventLog& log) {
  // An activation already accepted for the next tick boundary goes through: the discard is refused
  // (never acknowledged while the table it claims to drop is still activated).
  if (table_.staged()) {
    return CommandCheck{RejectReason::kBusy, 0,
                        "an activation is pending at the next tick: nothing to discard"};
  }
  if (!table_.loaded())
    return CommandCheck{RejectReason::kNothingToActivate, 0, "no parameter load"};
  table_.discard(active);
  log.emit(Severity::kInfo, EventId::kTableDiscarded, 0, 0,
           "inactive parameter table discarded (copy of the active one)");
  return CommandCheck{};
}

void ParamLifecycle::activate(gnc::Gnc& core, EventLog& log) {
  activation_ = table_.staged_table();
  activation_.law = core.params().law;  // the law is selected by command, not by the table
  const gnc::ParamCheck c = core.set_params(activation_);
  if (c.ok) {
    ++activations_;
    table_.activated(core.params());
    log.emit(Severity::kInfo, EventId::kTableActivated, static_cast<std::int32_t>(activations_), 0,
             "parameter table activated at the tick boundary");
  } else {
    table_.activation_failed();
    log.emit(Severity::kError, EventId::kTableActivationFailed, 0, 0,
             "parameter table activation failed: %s %s", c.field, c.reason);
  }
}

}  // namespace rocksteady::fsw
