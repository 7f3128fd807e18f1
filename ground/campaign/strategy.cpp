#include "ground/campaign/strategy.hpp"

namespace rocksteady::campaign {

namespace {

std::optional<Strategy> parse_base(const std::string& name) {
  if (name == "dpd") return Strategy{name, gnc::LawId::kDpd, ReferenceKind::kDpdRef};
  const std::size_t plus = name.find('+');
  if (plus == std::string::npos) return std::nullopt;
  const std::string law = name.substr(0, plus);
  const std::string ref = name.substr(plus + 1);
  Strategy s;
  s.name = name;
  if (ref == "dpd_ref") {
    s.reference = ReferenceKind::kDpdRef;
  } else if (ref == "fuel_optimal") {
    s.reference = ReferenceKind::kFuelOptimal;
  } else if (ref == "replan") {
    s.reference = ReferenceKind::kReplan;
    s.identify = true;  // the re-planner plans for the identified model
  } else if (ref == "fuel_optimal_study") {
    s.reference = ReferenceKind::kFuelOptimal;
    s.horizon = PlanHorizon::kStudy;
  } else {
    return std::nullopt;
  }
  for (int i = 0; i < gnc::kLawCount; ++i) {
    const auto id = static_cast<gnc::LawId>(i);
    if (id != gnc::LawId::kDpd && law == gnc::to_string(id)) {
      s.law = id;
      return s;
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<Strategy> parse_strategy(const std::string& name) {
  const std::size_t colon = name.find(':');
  std::optional<Strategy> s = parse_base(name.substr(0, colon));
  if (!s) return std::nullopt;
  s->name = name;
  std::size_t at = colon;
  bool id_given = false;  // ":id" given (replan implies it; it may still be written once)
  while (at != std::string::npos) {
    const std::size_t next = name.find(':', at + 1);
    const std::string mod = name.substr(at + 1, next == std::string::npos ? next : next - at - 1);
    const bool id_mod = mod == "id" || mod == "idx";
    bool& flag = mod == "mekf" ? s->mekf : id_mod ? id_given : s->fdi;
    if ((mod != "mekf" && !id_mod && mod != "fdi") || flag) return std::nullopt;
    if (id_mod) s->identify = true;
    if (mod == "idx") s->excite = true;
    flag = true;
    at = next;
  }
  return s;
}

const std::vector<std::string>& study_strategy_names() {
  static const std::vector<std::string> names = {"ntcl+fuel_optimal", "adaptive+fuel_optimal",
                                                 "el+fuel_optimal",   "ntcl+dpd_ref",
                                                 "adaptive+dpd_ref",  "dpd"};
  return names;
}

const std::vector<std::string>& all_strategy_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = study_strategy_names();
    n.push_back("feedforward+dpd_ref");
    n.push_back("feedforward+fuel_optimal");
    return n;
  }();
  return names;
}

}  // namespace rocksteady::campaign
