#include "ground/campaign/estimation_report.hpp"

namespace rocksteady::campaign {

namespace {
nlohmann::json opt(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}
std::optional<double> to_opt(const nlohmann::json& j) {
  if (j.is_null()) return std::nullopt;
  return j.get<double>();
}
}  // namespace

nlohmann::json estimation_json(const EstimationReport& e) {
  nlohmann::json marks = nlohmann::json::array();
  for (const IdentificationMark& m : e.marks) {
    marks.push_back({{"t_s", m.t_s},
                     {"reached", m.reached},
                     {"j_rel", m.j_rel},
                     {"r_err_m", m.r_err_m},
                     {"k_max_err", m.k_max_err},
                     {"j_nees", m.j_nees},
                     {"r_nees", m.r_nees},
                     {"inertia_confident", m.inertia_confident},
                     {"offset_confident", m.offset_confident},
                     {"offset_unobservable", m.offset_unobservable}});
  }
  nlohmann::json strengths = nlohmann::json::array();
  for (const StrengthMark& m : e.strengths) {
    strengths.push_back({{"first_fired_s", opt(m.first_fired_s)},
                         {"reached", m.reached},
                         {"err", m.err},
                         {"sigma", m.sigma},
                         {"confident", m.confident},
                         {"impulse_ns", m.impulse_ns}});
  }
  return {{"estimator", e.estimator},
          {"attitude_rms_rad", e.attitude_rms_rad},
          {"attitude_max_rad", e.attitude_max_rad},
          {"rate_rms_rad_s", e.rate_rms_rad_s},
          {"rate_max_rad_s", e.rate_max_rad_s},
          {"identifying", e.identifying},
          {"model_adoptions", e.model_adoptions},
          {"identification", marks},
          {"strengths_after_firing", strengths}};
}

nlohmann::json replan_json(const ReplanReport& r, bool with_wall) {
  nlohmann::json plans = nlohmann::json::array();
  for (const ReplanEvent& e : r.events) {
    nlohmann::json p = {{"trigger", e.trigger},
                        {"t_state_s", e.t_state_s},
                        {"t_due_s", e.t_due_s},
                        {"t_delivered_s", e.t_delivered_s},
                        {"ok", e.ok},
                        {"error", e.error},
                        {"identified_model", e.identified},
                        {"planned_fuel_kg", e.planned_fuel_kg},
                        {"t_final_s", e.t_final_s},
                        {"nodes", e.nodes},
                        {"iterations", e.iterations},
                        {"upload_id", e.upload_id}};
    if (with_wall) p["solve_wall_s"] = e.wall_s;
    plans.push_back(std::move(p));
  }
  return {{"enabled", r.enabled},   {"plans", r.plans},       {"failed", r.failed},
          {"delivered", r.delivered}, {"switched", r.switched}, {"refused", r.refused},
          {"events", plans}};
}

nlohmann::json fdi_json(const FdiReport& f) {
  return {{"enabled", f.enabled},
          {"first_suspicion_s", opt(f.first_suspicion_s)},
          {"first_confirmation_s", opt(f.first_confirmation_s)},
          {"thruster", f.thruster},
          {"kind", f.kind},
          {"confirmations", f.confirmations},
          {"confirmed_on", f.confirmed_on},
          {"confirmed_off", f.confirmed_off},
          {"confirmed_degraded", f.confirmed_degraded},
          {"factor", f.factor},
          {"valve_closed_s", opt(f.valve_closed_s)},
          {"suspicions", f.suspicions},
          {"checks", f.checks},
          {"checks_unfit", f.checks_unfit},
          {"surveys", f.surveys},
          {"balance_tests", f.balance_tests},
          {"balance_confirmations", f.balance_confirmations},
          {"fault_detected_s", opt(f.fault_detected_s)},
          {"fault_first_commanded_s", opt(f.fault_first_commanded_s)},
          {"fault_commanded_s", f.fault_commanded_s},
          {"fault_commanded_impulse_ns", f.fault_commanded_impulse_ns}};
}

FdiReport fdi_from_json(const nlohmann::json& j) {
  FdiReport f;
  f.enabled = j.at("enabled").get<bool>();
  f.first_suspicion_s = to_opt(j.at("first_suspicion_s"));
  f.first_confirmation_s = to_opt(j.at("first_confirmation_s"));
  f.thruster = j.at("thruster").get<int>();
  f.kind = j.at("kind").get<std::string>();
  f.confirmations = j.at("confirmations").get<int>();
  f.confirmed_on = j.at("confirmed_on").get<std::uint16_t>();
  f.confirmed_off = j.at("confirmed_off").get<std::uint16_t>();
  f.valve_closed_s = to_opt(j.at("valve_closed_s"));
  f.suspicions = j.at("suspicions").get<std::uint32_t>();
  if (j.contains("checks")) {  // (F19), newer draws
    f.checks = j.at("checks").get<std::uint32_t>();
    f.checks_unfit = j.at("checks_unfit").get<std::uint32_t>();
  }
  if (j.contains("surveys")) f.surveys = j.at("surveys").get<std::uint32_t>();  // (F36)
  if (j.contains("balance_tests")) {  // (F61)
    f.balance_tests = j.at("balance_tests").get<std::uint32_t>();
    f.balance_confirmations = j.at("balance_confirmations").get<std::uint32_t>();
  }
  // Absent from draws written before these were measured.
  if (j.contains("confirmed_degraded")) {
    f.confirmed_degraded = j.at("confirmed_degraded").get<std::uint16_t>();
    f.factor = j.at("factor").get<double>();
  }
  if (j.contains("fault_detected_s")) f.fault_detected_s = to_opt(j.at("fault_detected_s"));
  if (j.contains("fault_first_commanded_s")) {
    f.fault_first_commanded_s = to_opt(j.at("fault_first_commanded_s"));
    f.fault_commanded_s = j.at("fault_commanded_s").get<double>();
    f.fault_commanded_impulse_ns = j.at("fault_commanded_impulse_ns").get<double>();
  }
  return f;
}

ReplanReport replan_from_json(const nlohmann::json& j) {
  ReplanReport r;
  r.enabled = j.at("enabled").get<bool>();
  r.plans = j.at("plans").get<int>();
  r.failed = j.at("failed").get<int>();
  r.delivered = j.at("delivered").get<int>();
  r.switched = j.at("switched").get<int>();
  r.refused = j.at("refused").get<int>();
  for (const nlohmann::json& p : j.at("events")) {
    ReplanEvent e;
    e.trigger = p.at("trigger").get<std::string>();
    e.t_state_s = p.at("t_state_s").get<double>();
    e.t_due_s = p.at("t_due_s").get<double>();
    e.t_delivered_s = p.at("t_delivered_s").get<double>();
    e.ok = p.at("ok").get<bool>();
    e.error = p.at("error").get<std::string>();
    e.identified = p.at("identified_model").get<bool>();
    e.planned_fuel_kg = p.at("planned_fuel_kg").get<double>();
    e.t_final_s = p.at("t_final_s").get<double>();
    e.nodes = p.at("nodes").get<int>();
    e.iterations = p.at("iterations").get<int>();
    e.upload_id = p.at("upload_id").get<int>();
    if (p.contains("solve_wall_s")) e.wall_s = p.at("solve_wall_s").get<double>();
    r.events.push_back(std::move(e));
  }
  return r;
}

EstimationReport estimation_from_json(const nlohmann::json& j) {
  EstimationReport e;
  e.estimator = j.at("estimator").get<std::string>();
  e.attitude_rms_rad = j.at("attitude_rms_rad").get<double>();
  e.attitude_max_rad = j.at("attitude_max_rad").get<double>();
  e.rate_rms_rad_s = j.at("rate_rms_rad_s").get<double>();
  e.rate_max_rad_s = j.at("rate_max_rad_s").get<double>();
  e.identifying = j.at("identifying").get<bool>();
  e.model_adoptions = j.at("model_adoptions").get<std::uint32_t>();
  for (const nlohmann::json& m : j.at("identification")) {
    IdentificationMark x;
    x.t_s = m.at("t_s").get<double>();
    x.reached = m.at("reached").get<bool>();
    x.j_rel = m.at("j_rel").get<double>();
    x.r_err_m = m.at("r_err_m").get<double>();
    x.k_max_err = m.at("k_max_err").get<double>();
    x.j_nees = m.at("j_nees").get<double>();
    x.r_nees = m.at("r_nees").get<double>();
    x.inertia_confident = m.at("inertia_confident").get<bool>();
    x.offset_confident = m.at("offset_confident").get<bool>();
    x.offset_unobservable = m.at("offset_unobservable").get<int>();
    e.marks.push_back(x);
  }
  // Absent from draws written before it was measured.
  if (j.contains("strengths_after_firing")) {
    for (const nlohmann::json& m : j.at("strengths_after_firing")) {
      StrengthMark x;
      x.first_fired_s = to_opt(m.at("first_fired_s"));
      x.reached = m.at("reached").get<bool>();
      x.err = m.at("err").get<double>();
      x.sigma = m.at("sigma").get<double>();
      x.confident = m.at("confident").get<bool>();
      x.impulse_ns = m.at("impulse_ns").get<double>();
      e.strengths.push_back(x);
    }
  }
  return e;
}

}  // namespace rocksteady::campaign
