#include "ground/dispersion/stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <stdexcept>

namespace rocksteady::dispersion {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
std::string fmt(const char* f, double v) {  // f: a literal "%.Nf"/"%.Ng" of this file
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}
#pragma GCC diagnostic pop
std::string g9(double v) {
  return fmt("%.9g", v);
}
std::string opt9(const std::optional<double>& v) {
  return v ? g9(*v) : std::string();
}
std::string nc(const std::optional<double>& v, const char* f) {
  return v ? fmt(f, *v) : "—";
}

std::ofstream open_out(const std::string& path) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  return out;
}

// ||dJ|| of a draw: the flown value when something flew, else the sampled one.
double dj_of(const DrawResult& d) {
  return d.flown ? d.flown->delta_j_norm : d.sampled.delta_j_norm;
}

json opt_json(const std::optional<double>& v) {
  return v ? json(*v) : json(nullptr);
}
json pct_json(const Percentiles& p) {
  return {{"n", p.n},
          {"p5", opt_json(p.p5)},
          {"p50", opt_json(p.p50)},
          {"p95", opt_json(p.p95)},
          {"p99", opt_json(p.p99)}};
}

}  // namespace

std::pair<double, double> wilson_interval(int k, int n, double z) {
  if (n <= 0) return {0.0, 1.0};
  const double nn = n, p = static_cast<double>(k) / nn, z2 = z * z;
  const double centre = (p + z2 / (2.0 * nn)) / (1.0 + z2 / nn);
  const double half = z / (1.0 + z2 / nn) * std::sqrt(p * (1.0 - p) / nn + z2 / (4.0 * nn * nn));
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

std::optional<double> percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::nullopt;
  std::sort(v.begin(), v.end());
  const double h = (static_cast<double>(v.size()) - 1.0) * p;
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

Percentiles percentiles(const std::vector<double>& v) {
  Percentiles p;
  p.n = static_cast<int>(v.size());
  p.p5 = percentile(v, 0.05);
  p.p50 = percentile(v, 0.50);
  p.p95 = percentile(v, 0.95);
  p.p99 = percentile(v, 0.99);
  return p;
}

std::string declared_kind(plant::FaultKind k) {
  switch (k) {
    case plant::FaultKind::kStuckOn: return "stuck-on";
    case plant::FaultKind::kStuckOff: return "stuck-off";
    case plant::FaultKind::kDegraded: return "degraded";
    case plant::FaultKind::kNone: break;
  }
  return "none";
}

namespace {

// Per strategy x kind x onset (case 0) and x case: isolation and fuel penalty (FaultGroupStats).
void summarize_faults(const DispersionSpec& spec, const std::vector<DrawResult>& draws,
                      const std::vector<DrawResult>& references, Summary& s) {
  if (!spec.faults.enabled) return;
  for (const DrawResult& r : references) {
    for (const StrategyOutcome& o : r.runs) {
      s.references.push_back(
          {r.sampled.case_number, o.strategy, o.status, o.success, o.total_fuel_kg});
    }
  }
  auto reference_fuel = [&](int case_number, const std::string& strategy) -> std::optional<double> {
    for (const ReferenceRow& x : s.references) {
      if (x.case_number == case_number && x.strategy == strategy && x.status == "ok") {
        return x.fuel_kg;
      }
    }
    return std::nullopt;
  };
  std::vector<int> cases{0};  // 0: every case, then each study case of the plan
  for (int c : spec.faults.case_numbers) cases.push_back(c);
  for (std::size_t k = 0; k < spec.strategies.size(); ++k) {
    for (plant::FaultKind kind : spec.faults.kinds) {
      for (double onset : spec.faults.onsets_s) {
        for (int c : cases) {
          FaultGroupStats g;
          g.strategy = spec.strategies[k].name;
          g.kind = plant::to_string(kind);
          g.onset_s = onset;
          g.case_number = c;
          std::vector<double> lat, pen, cmd, imp, fire, det, valve;
          for (const DrawResult& d : draws) {
            if (!d.sampled.has_fault || d.sampled.fault.kind != kind ||
                d.sampled.fault.onset_s != onset || (c != 0 && d.sampled.case_number != c) ||
                k >= d.runs.size() || d.runs[k].status != "ok") {
              continue;
            }
            const StrategyOutcome& o = d.runs[k];
            ++g.runs;
            g.successes += o.success ? 1 : 0;
            g.goals_met += o.t_omega_conv_s && o.t_q_conv_s ? 1 : 0;
            const campaign::FdiReport& f = o.fdi;
            if (!f.fault_first_commanded_s) ++g.not_commanded;
            // Detected: the first window above the no-fault bound after onset, or the first
            // confirmation if that came first (F14 confirms from the identifier's fault torque).
            std::optional<double> detected = f.fault_detected_s;
            if (f.first_confirmation_s && *f.first_confirmation_s >= onset &&
                (!detected || *f.first_confirmation_s < *detected)) {
              detected = f.first_confirmation_s;
            }
            if (detected) {
              ++g.detected;
              det.push_back(*detected - onset);
            }
            if (f.confirmations == 0) {
              ++g.none;
            } else if (f.confirmations == 1 && f.thruster == d.sampled.fault.thruster &&
                       f.kind == declared_kind(kind) && f.first_confirmation_s) {
              ++g.isolated;
              lat.push_back(*f.first_confirmation_s - onset);
              cmd.push_back(f.fault_commanded_s);
              imp.push_back(f.fault_commanded_impulse_ns);
              if (d.flown && d.flown->u_max_true_n > 0.0) {
                fire.push_back(f.fault_commanded_impulse_ns / d.flown->u_max_true_n);
              }
              if (kind == plant::FaultKind::kStuckOn && f.valve_closed_s &&
                  *f.valve_closed_s >= onset) {
                valve.push_back(*f.valve_closed_s - onset);
              }
            } else {
              ++g.wrong;
            }
            const std::optional<double> ref = reference_fuel(d.sampled.case_number, o.strategy);
            if (ref && o.total_fuel_kg) pen.push_back(*o.total_fuel_kg - *ref);
          }
          if (g.runs == 0) continue;
          g.latency_s = percentiles(lat);
          if (!lat.empty()) g.latency_max_s = *std::max_element(lat.begin(), lat.end());
          g.detection_s = percentiles(det);
          if (!det.empty()) g.detection_max_s = *std::max_element(det.begin(), det.end());
          g.valve_s = percentiles(valve);
          if (!valve.empty()) g.valve_max_s = *std::max_element(valve.begin(), valve.end());
          g.commanded_to_isolation_s = percentiles(cmd);
          g.commanded_impulse_to_isolation_ns = percentiles(imp);
          g.firing_to_isolation_s = percentiles(fire);
          if (!fire.empty()) g.firing_to_isolation_max_s = *std::max_element(fire.begin(), fire.end());
          if (!cmd.empty()) g.commanded_to_isolation_max_s = *std::max_element(cmd.begin(), cmd.end());
          g.penalty_kg = percentiles(pen);
          if (!pen.empty()) g.penalty_max_kg = *std::max_element(pen.begin(), pen.end());
          s.faults.push_back(g);
        }
      }
    }
  }
}

}  // namespace

Summary summarize(const DispersionSpec& spec, const std::vector<DrawResult>& draws,
                  const std::vector<DrawResult>& references) {
  Summary s;
  s.name = spec.name;
  s.draws_expected = spec.draws;
  s.draws_present = static_cast<int>(draws.size());
  const std::size_t ns = spec.strategies.size();
  for (const DrawResult& d : draws) {
    s.draw_wall_s_sum += d.wall_s;
    s.plan_wall_s_sum += d.plan_wall_s;
    for (const StrategyOutcome& o : d.runs) {
      s.simulated_s += o.sim_s;
      s.closed_loop_wall_s_sum += o.wall_s;
    }
  }
  for (std::size_t k = 0; k < ns; ++k) {
    StrategyStats st;
    st.strategy = spec.strategies[k].name;
    std::vector<double> tw, tq, fuel;
    struct Rank {
      int severity;  // 3 error/crash, 2 no plan, 1 not successful, 0 success
      double fuel;
      int draw;
      std::string why;
      std::optional<double> f;
    };
    std::vector<Rank> ranks;
    for (const DrawResult& d : draws) {
      if (k >= d.runs.size()) continue;
      const StrategyOutcome& o = d.runs[k];
      ++st.draws;
      Rank r{0, 0.0, d.index, "", o.total_fuel_kg};
      if (o.status == "ok") {
        ++st.flown;
        if (o.success) ++st.successes;
        if (o.t_omega_conv_s) tw.push_back(*o.t_omega_conv_s);
        if (o.t_q_conv_s) tq.push_back(*o.t_q_conv_s);
        if (o.total_fuel_kg) fuel.push_back(*o.total_fuel_kg);
        r.fuel = o.total_fuel_kg.value_or(0.0);
        if (!o.success) {
          r.severity = 1;
          if (!o.t_omega_conv_s) {
            r.why = "rate goal not met";
          } else if (!o.t_q_conv_s) {
            r.why = "attitude goal not met";
          } else {
            r.why = "max |omega| " + fmt("%.4g", o.max_rate_rad_s) + " rad/s above eps_trans";
          }
        } else {
          r.why = "fuel " + fmt("%.2f", r.fuel) + " kg";
        }
      } else if (o.status == "no_plan") {
        ++st.no_plan;
        r.severity = 2;
        r.why = "no plan: " + o.note;
      } else {
        ++st.errors;
        r.severity = 3;
        r.why = o.status + ": " + o.note;
      }
      ranks.push_back(r);
    }
    st.success_rate = st.draws > 0 ? static_cast<double>(st.successes) / st.draws : 0.0;
    st.wilson = wilson_interval(st.successes, st.draws);
    st.t_omega = percentiles(tw);
    st.t_q = percentiles(tq);
    st.fuel = percentiles(fuel);
    std::vector<double> att, rate;
    for (const DrawResult& d : draws) {
      if (k >= d.runs.size() || d.runs[k].status != "ok") continue;
      const campaign::EstimationReport& e = d.runs[k].estimation;
      att.push_back(e.attitude_rms_rad);
      rate.push_back(e.rate_rms_rad_s);
      for (std::size_t m = 0; m < e.marks.size(); ++m) {
        if (!e.marks[m].reached) continue;
        if (st.identification.size() <= m) st.identification.resize(m + 1);
        st.identification[m].t_s = e.marks[m].t_s;
      }
    }
    st.attitude_rms_rad = percentiles(att);
    st.rate_rms_rad_s = percentiles(rate);
    for (std::size_t m = 0; m < st.identification.size(); ++m) {
      IdentificationStats& is = st.identification[m];
      std::vector<double> j, r, kk;
      int j_in = 0, r_in = 0;
      for (const DrawResult& d : draws) {
        if (k >= d.runs.size() || d.runs[k].status != "ok") continue;
        const campaign::EstimationReport& e = d.runs[k].estimation;
        if (m >= e.marks.size() || !e.marks[m].reached) continue;
        const campaign::IdentificationMark& x = e.marks[m];
        j.push_back(x.j_rel);
        r.push_back(x.r_err_m);
        kk.push_back(x.k_max_err);
        j_in += x.j_nees <= campaign::kChi2Dof6P95 ? 1 : 0;
        r_in += x.r_nees <= campaign::kChi2Dof3P95 ? 1 : 0;
        is.inertia_confident += x.inertia_confident ? 1 : 0;
        is.offset_confident += x.offset_confident ? 1 : 0;
      }
      is.n = static_cast<int>(j.size());
      is.j_rel = percentiles(j);
      is.r_err_m = percentiles(r);
      is.k_max_err = percentiles(kk);
      is.j_nees_in95 = is.n > 0 ? static_cast<double>(j_in) / is.n : 0.0;
      is.r_nees_in95 = is.n > 0 ? static_cast<double>(r_in) / is.n : 0.0;
    }
    {
      StrengthStats& ks = st.strengths;
      std::vector<double> worst, all, worst_conf;
      int within = 0, nees_in = 0;
      for (const DrawResult& d : draws) {
        if (k >= d.runs.size() || d.runs[k].status != "ok") continue;
        double w = -1.0, wc = -1.0;
        for (const campaign::StrengthMark& m : d.runs[k].estimation.strengths) {
          if (!m.first_fired_s) ++ks.never_fired;
          if (!m.reached) continue;
          ++ks.pairs;
          all.push_back(m.err);
          w = std::max(w, m.err);
          within += m.err <= 0.02 ? 1 : 0;
          const double z = m.sigma > 0.0 ? m.err / m.sigma : std::numeric_limits<double>::infinity();
          nees_in += z * z <= campaign::kChi2Dof1P95 ? 1 : 0;
          if (m.confident) {
            ++ks.confident;
            wc = std::max(wc, m.err);
          }
        }
        if (w >= 0.0) {
          ++ks.draws;
          worst.push_back(w);
        }
        if (wc >= 0.0) worst_conf.push_back(wc);
      }
      ks.worst = percentiles(worst);
      ks.all = percentiles(all);
      ks.worst_confident = percentiles(worst_conf);
      ks.within_2pct = ks.pairs > 0 ? static_cast<double>(within) / ks.pairs : 0.0;
      ks.nees_in95 = ks.pairs > 0 ? static_cast<double>(nees_in) / ks.pairs : 0.0;
    }
    std::stable_sort(ranks.begin(), ranks.end(), [](const Rank& x, const Rank& y) {
      if (x.severity != y.severity) return x.severity > y.severity;
      if (x.fuel != y.fuel) return x.fuel > y.fuel;
      return x.draw < y.draw;
    });
    for (std::size_t i = 0; i < ranks.size() && i < 5; ++i) {
      st.worst.push_back({ranks[i].draw, ranks[i].why, ranks[i].f});
    }
    s.strategies.push_back(st);
  }
  // Paired fuel differences on the same draws.
  for (std::size_t a = 0; a < ns; ++a) {
    for (std::size_t b = a + 1; b < ns; ++b) {
      PairedStats p;
      p.a = spec.strategies[a].name;
      p.b = spec.strategies[b].name;
      std::vector<double> diff;
      int less = 0;
      for (const DrawResult& d : draws) {
        if (b >= d.runs.size()) continue;
        const auto& fa = d.runs[a].total_fuel_kg;
        const auto& fb = d.runs[b].total_fuel_kg;
        if (d.runs[a].status != "ok" || d.runs[b].status != "ok" || !fa || !fb) continue;
        diff.push_back(*fa - *fb);
        if (*fa < *fb) ++less;
      }
      p.n = static_cast<int>(diff.size());
      double sum = 0.0;
      for (double x : diff) sum += x;
      p.mean_diff_kg = p.n > 0 ? sum / p.n : 0.0;
      p.frac_a_less = p.n > 0 ? static_cast<double>(less) / p.n : 0.0;
      p.diff = percentiles(diff);
      s.paired.push_back(p);
    }
  }
  // Prop. 5 crossovers: law+fuel_optimal against law+dpd_ref, binned in log ||dJ||.
  double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
  for (const DrawResult& d : draws) {
    const double dj = dj_of(d);
    if (dj > 0.0) {
      lo = std::min(lo, dj);
      hi = std::max(hi, dj);
    }
  }
  if (hi > lo) {
    for (std::size_t a = 0; a < ns; ++a) {
      const campaign::Strategy& sa = spec.strategies[a];
      if (!sa.needs_trajectory()) continue;
      for (std::size_t b = 0; b < ns; ++b) {
        const campaign::Strategy& sb = spec.strategies[b];
        if (sb.needs_trajectory() || sb.law != sa.law || sb.name == "dpd") continue;
        Crossover c;
        c.a = sa.name;
        c.b = sb.name;
        const double l0 = std::log10(lo), l1 = std::log10(hi);
        const int nbins = std::max(1, std::min(12, static_cast<int>(std::ceil((l1 - l0) * 2.0))));
        std::vector<std::vector<double>> bins(static_cast<std::size_t>(nbins));
        for (const DrawResult& d : draws) {
          const double dj = dj_of(d);
          if (!(dj > 0.0) || b >= d.runs.size()) continue;
          const auto& fa = d.runs[a].total_fuel_kg;
          const auto& fb = d.runs[b].total_fuel_kg;
          if (d.runs[a].status != "ok" || d.runs[b].status != "ok" || !fa || !fb) continue;
          int i = static_cast<int>((std::log10(dj) - l0) / (l1 - l0) * nbins);
          i = std::max(0, std::min(nbins - 1, i));
          bins[static_cast<std::size_t>(i)].push_back(*fa - *fb);
        }
        std::vector<double> centre;
        for (int i = 0; i < nbins; ++i) {
          c.bin_lo.push_back(std::pow(10.0, l0 + (l1 - l0) * i / nbins));
          c.bin_hi.push_back(std::pow(10.0, l0 + (l1 - l0) * (i + 1) / nbins));
          centre.push_back(l0 + (l1 - l0) * (i + 0.5) / nbins);
          const auto& v = bins[static_cast<std::size_t>(i)];
          c.bin_n.push_back(static_cast<int>(v.size()));
          c.bin_median_diff.push_back(v.empty() ? std::nan("") : *percentile(v, 0.5));
        }
        // First change from a negative median (fuel-optimal cheaper) to a positive one.
        int prev = -1;
        for (int i = 0; i < nbins; ++i) {
          const double m = c.bin_median_diff[static_cast<std::size_t>(i)];
          if (std::isnan(m)) continue;
          if (prev >= 0) {
            const double mp = c.bin_median_diff[static_cast<std::size_t>(prev)];
            if (mp < 0.0 && m >= 0.0) {
              const double x0 = centre[static_cast<std::size_t>(prev)];
              const double x1 = centre[static_cast<std::size_t>(i)];
              c.crossover_kg_m2 = std::pow(10.0, x0 + (x1 - x0) * (-mp) / (m - mp));
              break;
            }
          }
          prev = i;
        }
        s.crossovers.push_back(c);
      }
    }
  }
  summarize_faults(spec, draws, references, s);
  return s;
}

void write_results_csv(const std::string& path, const DispersionSpec& spec,
                       const std::vector<DrawResult>& draws) {
  (void)spec;
  std::ofstream out = open_out(path);
  out << "draw,strategy,status,success,t_omega_conv_s,fuel_at_t_omega_kg,t_q_conv_s,fuel_at_t_q_kg,"
         "total_fuel_kg,max_rate_rad_s,final_mode,delta_j_ast_norm_kg_m2,delta_r_so_bcm_norm_m,"
         "initial_rate_norm_rad_s,gyro_noise_psd_rad2_s2,star_noise_psd,disturbance_sigma_nm,"
         "u_max_n,noise_seed,pd_redraws,note,case,fault\n";
  for (const DrawResult& d : draws) {
    for (const StrategyOutcome& o : d.runs) {
      std::string note = o.note;
      std::replace(note.begin(), note.end(), ',', ';');
      std::replace(note.begin(), note.end(), '\n', ' ');
      out << d.index << "," << o.strategy << "," << o.status << "," << (o.success ? 1 : 0) << ","
          << opt9(o.t_omega_conv_s) << "," << opt9(o.fuel_at_t_omega_kg) << ","
          << opt9(o.t_q_conv_s) << "," << opt9(o.fuel_at_t_q_kg) << "," << opt9(o.total_fuel_kg)
          << "," << (o.status == "ok" ? g9(o.max_rate_rad_s) : "") << "," << o.final_mode << ",";
      if (d.flown) {  // read back from the models flown
        const Readback& b = *d.flown;
        out << g9(b.delta_j_norm) << "," << g9(b.delta_r_norm) << "," << g9(b.omega0.norm()) << ","
            << g9(b.gyro_psd) << "," << g9(b.star_psd) << "," << g9(b.disturbance_sigma_nm) << ","
            << g9(b.u_max_true_n) << "," << b.noise_seed;
      } else {
        out << ",,,,,,,";
      }
      out << "," << d.sampled.pd_redraws << "," << note << ","
          << (d.sampled.case_number > 0 ? std::to_string(d.sampled.case_number) : std::string()) << ","
          << (d.flown ? d.flown->faults
                      : (d.sampled.has_fault ? plant::describe(d.sampled.fault) : std::string("none")))
          << "\n";
    }
  }
}

json summary_json(const Summary& s, const std::string& reproduce) {
  json strategies = json::array();
  for (const StrategyStats& st : s.strategies) {
    json worst = json::array();
    for (const WorstDraw& w : st.worst) {
      worst.push_back({{"draw", w.draw},
                       {"why", w.why},
                       {"total_fuel_kg", opt_json(w.fuel_kg)},
                       {"reproduce", reproduce + " --draw " + std::to_string(w.draw)}});
    }
    json id = json::array();
    for (const IdentificationStats& is : st.identification) {
      id.push_back({{"t_s", is.t_s},
                    {"n", is.n},
                    {"j_rel", pct_json(is.j_rel)},
                    {"r_err_m", pct_json(is.r_err_m)},
                    {"k_max_err", pct_json(is.k_max_err)},
                    {"j_nees_in_chi2_95", is.j_nees_in95},
                    {"r_nees_in_chi2_95", is.r_nees_in95},
                    {"inertia_confident", is.inertia_confident},
                    {"offset_confident", is.offset_confident}});
    }
    const StrengthStats& ks = st.strengths;
    const json strengths = {{"after_first_firing_s", campaign::kStrengthMarkAfterFiringS},
                            {"draws", ks.draws},
                            {"pairs", ks.pairs},
                            {"never_fired", ks.never_fired},
                            {"worst_per_draw", pct_json(ks.worst)},
                            {"all", pct_json(ks.all)},
                            {"within_2pct", ks.within_2pct},
                            {"nees_in_chi2_95", ks.nees_in95},
                            {"confident", ks.confident},
                            {"worst_confident_per_draw", pct_json(ks.worst_confident)}};
    const json estimation = {{"attitude_rms_rad", pct_json(st.attitude_rms_rad)},
                             {"rate_rms_rad_s", pct_json(st.rate_rms_rad_s)},
                             {"identification", id},
                             {"strengths_after_firing", strengths}};
    strategies.push_back({{"strategy", st.strategy},
                          {"draws", st.draws},
                          {"flown", st.flown},
                          {"successes", st.successes},
                          {"no_plan", st.no_plan},
                          {"errors", st.errors},
                          {"success_rate", st.success_rate},
                          {"success_wilson95", {st.wilson.first, st.wilson.second}},
                          {"t_omega_conv_s", pct_json(st.t_omega)},
                          {"t_q_conv_s", pct_json(st.t_q)},
                          {"total_fuel_kg", pct_json(st.fuel)},
                          {"worst_draws", worst},
                          {"estimation", estimation}});
  }
  json paired = json::array();
  for (const PairedStats& p : s.paired) {
    paired.push_back({{"a", p.a},
                      {"b", p.b},
                      {"n", p.n},
                      {"mean_fuel_diff_kg", p.mean_diff_kg},
                      {"fuel_diff_kg", pct_json(p.diff)},
                      {"fraction_a_uses_less", p.frac_a_less}});
  }
  json cross = json::array();
  for (const Crossover& c : s.crossovers) {
    json bins = json::array();
    for (std::size_t i = 0; i < c.bin_n.size(); ++i) {
      const double m = c.bin_median_diff[i];
      bins.push_back({{"delta_j_lo", c.bin_lo[i]},
                      {"delta_j_hi", c.bin_hi[i]},
                      {"n", c.bin_n[i]},
                      {"median_fuel_diff_kg", std::isnan(m) ? json(nullptr) : json(m)}});
    }
    cross.push_back({{"fuel_optimal", c.a},
                     {"dpd_based", c.b},
                     {"bins", bins},
                     {"crossover_delta_j_kg_m2", opt_json(c.crossover_kg_m2)}});
  }
  json faults = json::array();
  for (const FaultGroupStats& g : s.faults) {
    faults.push_back({{"strategy", g.strategy},
                      {"kind", g.kind},
                      {"onset_s", g.onset_s},
                      {"case", g.case_number},
                      {"runs", g.runs},
                      {"goals_met", g.goals_met},
                      {"successes", g.successes},
                      {"isolated", g.isolated},
                      {"wrong", g.wrong},
                      {"none", g.none},
                      {"latency_s", pct_json(g.latency_s)},
                      {"latency_max_s", opt_json(g.latency_max_s)},
                      {"detected", g.detected},
                      {"detection_s", pct_json(g.detection_s)},
                      {"detection_max_s", opt_json(g.detection_max_s)},
                      {"valve_s", pct_json(g.valve_s)},
                      {"valve_max_s", opt_json(g.valve_max_s)},
                      {"fuel_penalty_kg", pct_json(g.penalty_kg)},
                      {"fuel_penalty_max_kg", opt_json(g.penalty_max_kg)},
                      {"not_commanded", g.not_commanded},
                      {"commanded_to_isolation_s", pct_json(g.commanded_to_isolation_s)},
                      {"commanded_to_isolation_max_s", opt_json(g.commanded_to_isolation_max_s)},
                      {"commanded_impulse_to_isolation_ns",
                       pct_json(g.commanded_impulse_to_isolation_ns)},
                      {"firing_to_isolation_s", pct_json(g.firing_to_isolation_s)},
                      {"firing_to_isolation_max_s", opt_json(g.firing_to_isolation_max_s)}});
  }
  json refs = json::array();
  for (const ReferenceRow& r : s.references) {
    refs.push_back({{"case", r.case_number},
                    {"strategy", r.strategy},
                    {"status", r.status},
                    {"success", r.success},
                    {"total_fuel_kg", opt_json(r.fuel_kg)}});
  }
  return {{"name", s.name},
          {"draws_expected", s.draws_expected},
          {"draws_present", s.draws_present},
          {"strategies", strategies},
          {"paired_fuel", paired},
          {"prop5_crossover", cross},
          {"faults", faults},
          {"fault_free_references", refs},
          {"timing",
           {{"simulated_s", s.simulated_s},
            {"closed_loop_cpu_wall_s", s.closed_loop_wall_s_sum},
            {"sim_s_per_wall_s_per_worker",
             s.closed_loop_wall_s_sum > 0 ? s.simulated_s / s.closed_loop_wall_s_sum : 0.0},
            {"planning_wall_s", s.plan_wall_s_sum},
            {"draws_wall_s", s.draw_wall_s_sum}}}};
}

OutputPaths write_outputs(const std::string& dir, const DispersionSpec& spec,
                          const std::vector<DrawResult>& draws, const Summary& s,
                          const std::string& reproduce, bool plots) {
  OutputPaths p;
  const fs::path d(dir);
  p.results_csv = (d / "results.csv").string();
  p.summary_json = (d / "summary.json").string();
  p.report_md = (d / "report.md").string();
  write_results_csv(p.results_csv, spec, draws);
  {
    std::ofstream out = open_out(p.summary_json);
    out << summary_json(s, reproduce).dump(2) << "\n";
  }
  // Plot data and scripts.
  if (plots) {
    const fs::path pd = d / "plots";
    fs::create_directories(pd);
    const std::size_t ns = spec.strategies.size();
    bool dj_log = true;
    for (const DrawResult& x : draws) dj_log = dj_log && dj_of(x) > 0.0;
    for (std::size_t k = 0; k < ns; ++k) {
      std::vector<double> fuel;
      std::ofstream pts = open_out((pd / ("draws_" + std::to_string(k) + ".dat")).string());
      pts << "# delta_j_norm total_fuel_kg success t_q_conv_s\n";
      for (const DrawResult& x : draws) {
        if (k >= x.runs.size()) continue;
        const StrategyOutcome& o = x.runs[k];
        if (o.total_fuel_kg) fuel.push_back(*o.total_fuel_kg);
        pts << g9(dj_of(x)) << " " << (o.total_fuel_kg ? g9(*o.total_fuel_kg) : "NaN") << " "
            << (o.success ? 1 : 0) << " " << (o.t_q_conv_s ? g9(*o.t_q_conv_s) : "NaN") << "\n";
      }
      std::sort(fuel.begin(), fuel.end());
      std::ofstream cdf = open_out((pd / ("fuel_cdf_" + std::to_string(k) + ".dat")).string());
      for (std::size_t i = 0; i < fuel.size(); ++i) {
        cdf << g9(fuel[i]) << " "
            << g9(static_cast<double>(i + 1) / static_cast<double>(fuel.size())) << "\n";
      }
    }
    std::ofstream gp = open_out((pd / "plots.gp").string());
    gp << "# Rocksteady dispersion plots, generated by rocksteady-campaign.\n"
       << "set terminal pngcairo size 1000,700 noenhanced font ',10'\nset grid\nset key outside "
          "right\n";
    auto each = [&](const std::string& body) {
      for (std::size_t k = 0; k < ns; ++k) {
        std::string b = body;
        for (std::size_t pos; (pos = b.find("@K")) != std::string::npos;) {
          b.replace(pos, 2, std::to_string(k));
        }
        for (std::size_t pos; (pos = b.find("@S")) != std::string::npos;) {
          b.replace(pos, 2, spec.strategies[k].name);
        }
        gp << (k == 0 ? "plot " : ", ") << b;
      }
      gp << "\n";
    };
    gp << "set output 'fuel_cdf.png'\nset title '" << spec.name
       << ": total fuel, empirical CDF per strategy'\nset xlabel 'total fuel (kg)'\n"
       << "set ylabel 'fraction of draws'\n";
    each("'fuel_cdf_@K.dat' using 1:2 with steps lw 2 title '@S'");
    gp << "set output 'fuel_vs_dj.png'\nset title '" << spec.name
       << ": total fuel vs ||dJ_ast||'\nset xlabel '||dJ_ast|| (kg m^2)'\nset ylabel 'total fuel "
          "(kg)'\n"
       << (dj_log ? "set logscale x\n" : "");
    each("'draws_@K.dat' using 1:2 with points pt 7 ps 0.6 title '@S'");
    gp << "set output 'success_vs_dj.png'\nset title '" << spec.name
       << ": success (1) or not (0) vs ||dJ_ast||, jittered per strategy'\nset ylabel 'success'\n"
       << "set yrange [-0.3:1.3]\n";
    for (std::size_t k = 0; k < ns; ++k) {
      gp << (k == 0 ? "plot " : ", ") << "'draws_" << k << ".dat' using 1:($3 + "
         << g9(0.03 * static_cast<double>(k)) << ") with points pt 7 ps 0.6 title '"
         << spec.strategies[k].name << "'";
    }
    gp << "\nunset logscale x\nset yrange [*:*]\nset output 'tq_hist.png'\nset title '" << spec.name
       << ": t_q,conv histogram (converged draws)'\nset xlabel 't_q,conv (s)'\n"
       << "set ylabel 'draws'\nbin(x) = 2000.0 * floor(x / 2000.0) + 1000.0\nset style fill "
          "transparent solid 0.35\n";
    each("'draws_@K.dat' using (bin($4)):(1.0) smooth frequency with boxes title '@S'");
    gp.close();
    const std::string cmd = "cd '" + pd.string() + "' && gnuplot plots.gp > plots.log 2>&1";
    if (std::system(cmd.c_str()) == 0) {
      for (const char* f : {"fuel_cdf.png", "fuel_vs_dj.png", "success_vs_dj.png", "tq_hist.png"}) {
        p.plots.push_back((pd / f).string());
      }
    }
  }
  // The report.
  std::ofstream md = open_out(p.report_md);
  md << "# Dispersion `" << spec.name << "`\n\n"
     << spec.description << "\n\n"
     << "File `" << spec.file << "`, master seed " << spec.master_seed << ", sampling "
     << to_string(spec.sampling) << ", " << s.draws_present << " of " << s.draws_expected
     << " draws, " << spec.duration_s << " s each.\n\n"
     << "Success: both SPEC §7 goals met and ‖ω‖ ≤ ε_trans throughout. Intervals: 95 % Wilson. "
        "Percentiles over the draws that converged (t) or flew (fuel).\n\n"
     << "| strategy | success | 95 % CI | no plan | errors | t_ω,conv p5/p50/p95/p99 (s) | "
        "t_q,conv p5/p50/p95/p99 (s) | fuel p5/p50/p95/p99 (kg) "
        "|\n|---|---:|---|---:|---:|---|---|---|\n";
  auto four = [](const Percentiles& q, const char* f) {
    return nc(q.p5, f) + " / " + nc(q.p50, f) + " / " + nc(q.p95, f) + " / " + nc(q.p99, f);
  };
  for (const StrategyStats& st : s.strategies) {
    md << "| `" << st.strategy << "` | " << st.successes << "/" << st.draws << " ("
       << fmt("%.1f", 100.0 * st.success_rate) << " %) | " << fmt("%.1f", 100.0 * st.wilson.first)
       << "–" << fmt("%.1f", 100.0 * st.wilson.second) << " % | " << st.no_plan << " | "
       << st.errors << " | " << four(st.t_omega, "%.0f") << " | " << four(st.t_q, "%.0f") << " | "
       << four(st.fuel, "%.1f") << " |\n";
  }
  bool any_id = false;
  for (const StrategyStats& st : s.strategies) any_id = any_id || !st.identification.empty();
  md << "\n## Estimation against the truth\n\nAttitude and rate error RMS of the estimate (t ≥ 60 s), "
        "p50 / p95.\n\n| strategy | attitude (rad) | rate (rad/s) |\n|---|---|---|\n";
  for (const StrategyStats& st : s.strategies) {
    md << "| `" << st.strategy << "` | " << nc(st.attitude_rms_rad.p50, "%.2e") << " / "
       << nc(st.attitude_rms_rad.p95, "%.2e") << " | " << nc(st.rate_rms_rad_s.p50, "%.2e")
       << " / " << nc(st.rate_rms_rad_s.p95, "%.2e") << " |\n";
  }
  if (any_id) {
    md << "\n## Identification against the truth\n\n‖Ĵ−J‖/‖J‖, ‖r̂−r‖ (m), max|k̂−k|: p50 / p95 "
          "over the draws; NEES in 95 %: fraction of draws whose normalised error is inside the "
          "chi-square 95 % bound (≈ 0.95 when the 1σ is consistent).\n\n| strategy | t (s) | n | J "
          "| r (m) | k | J NEES in 95 % | r NEES in 95 % |\n|---|---:|---:|---|---|---|---:|---:|\n";
    for (const StrategyStats& st : s.strategies) {
      for (const IdentificationStats& is : st.identification) {
        md << "| `" << st.strategy << "` | " << fmt("%.0f", is.t_s) << " | " << is.n << " | "
           << nc(is.j_rel.p50, "%.1e") << " / " << nc(is.j_rel.p95, "%.1e") << " | "
           << nc(is.r_err_m.p50, "%.3f") << " / " << nc(is.r_err_m.p95, "%.3f") << " | "
           << nc(is.k_max_err.p50, "%.3f") << " / " << nc(is.k_max_err.p95, "%.3f") << " | "
           << fmt("%.2f", is.j_nees_in95) << " | " << fmt("%.2f", is.r_nees_in95) << " |\n";
      }
    }
    md << "\nThruster strengths 600 s after each thruster's first commanded firing (the pairs "
          "(draw, thruster) whose run lasted that long): |k̂−k| worst thruster per draw and over "
          "every pair, p50 / p95 / p99; the fraction within 2 %; NEES in 95 %: (|k̂−k|/1σ)² inside "
          "the chi-square (1 dof) 95 % bound; the worst confident thruster per draw.\n\n"
          "| strategy | draws | pairs | never fired | worst per draw | every pair | within 2 % | "
          "NEES in 95 % | confident | worst confident per draw |\n"
          "|---|---:|---:|---:|---|---|---:|---:|---:|---|\n";
    for (const StrategyStats& st : s.strategies) {
      if (st.identification.empty()) continue;
      const StrengthStats& ks = st.strengths;
      auto three = [&](const Percentiles& q) {
        return nc(q.p50, "%.4f") + " / " + nc(q.p95, "%.4f") + " / " + nc(q.p99, "%.4f");
      };
      md << "| `" << st.strategy << "` | " << ks.draws << " | " << ks.pairs << " | "
         << ks.never_fired << " | " << three(ks.worst) << " | " << three(ks.all) << " | "
         << fmt("%.3f", ks.within_2pct) << " | " << fmt("%.2f", ks.nees_in95) << " | "
         << ks.confident << " | " << three(ks.worst_confident) << " |\n";
    }
  }
  bool any_fdi = false;
  for (const DrawResult& dr : draws) {
    for (const StrategyOutcome& o : dr.runs) any_fdi = any_fdi || o.fdi.enabled;
  }
  if (any_fdi) {
    md << "\n## Fault detection\n\nPer strategy: runs flown with the detector, runs with at least "
          "one confirmed fault, with a window above the no-fault bound, with a latch valve "
          "closed, and with a jet check (F19; the checks started in all).\n\n| strategy | runs | "
          "confirmed | suspected | valve closed | jet checked (checks) |\n"
          "|---|---:|---:|---:|---:|---:|\n";
    for (std::size_t k = 0; k < spec.strategies.size(); ++k) {
      int n = 0, conf = 0, susp = 0, valve = 0, checked = 0;
      std::uint64_t checks = 0;
      for (const DrawResult& dr : draws) {
        if (k >= dr.runs.size() || !dr.runs[k].fdi.enabled) continue;
        const campaign::FdiReport& f = dr.runs[k].fdi;
        ++n;
        conf += f.confirmations > 0 ? 1 : 0;
        susp += f.suspicions > 0 ? 1 : 0;
        valve += f.valve_closed_s ? 1 : 0;
        checked += f.checks > 0 ? 1 : 0;
        checks += f.checks;
      }
      md << "| `" << spec.strategies[k].name << "` | " << n << " | " << conf << " | " << susp
         << " | " << valve << " | " << checked << " (" << checks << ") |\n";
    }
  }
  if (!s.faults.empty()) {
    md << "\n## Thruster faults\n\nPer strategy, fault kind and onset, over the study cases: "
          "runs, both SPEC §7 goals met (t_ω,conv and t_q,conv reached), success (the goals and "
          "‖ω‖ ≤ ε_trans throughout), the fault isolated (exactly one confirmation, "
          "naming the draw's thruster and kind), a wrong confirmation (another thruster or kind, "
          "or more than one), none; the latency from onset to the confirmation over the isolated "
          "runs (for stuck-off and degraded faults it includes the time before the jet is next "
          "commanded); the fuel penalty against the same case flown by the same strategy without "
          "the fault";
    if (s.references.empty()) md << " (no fault-free reference: the plan has no study cases)";
    md << ".\n\n| strategy | fault | onset (s) | runs | SPEC §7 goals | success | isolated | wrong | "
          "none | latency p50 / p95 / max (s) | fuel penalty p50 / p95 / max (kg) |\n"
          "|---|---|---:|---:|---:|---:|---:|---:|---:|---|---|\n";
    for (const FaultGroupStats& g : s.faults) {
      if (g.case_number != 0) continue;
      md << "| `" << g.strategy << "` | " << g.kind << " | " << fmt("%.0f", g.onset_s) << " | "
         << g.runs << " | " << g.goals_met << " | " << g.successes << " | " << g.isolated << " | "
         << g.wrong << " | "
         << g.none << " | " << nc(g.latency_s.p50, "%.1f") << " / " << nc(g.latency_s.p95, "%.1f")
         << " / " << nc(g.latency_max_s, "%.1f") << " | " << nc(g.penalty_kg.p50, "%.2f")
         << " / " << nc(g.penalty_kg.p95, "%.2f") << " / " << nc(g.penalty_max_kg, "%.2f")
         << " |\n";
    }
    md << "\nOver every fault kind and onset:\n\n";
    for (const campaign::Strategy& st : spec.strategies) {
      int runs = 0, goals = 0, ok = 0, isolated = 0, wrong = 0;
      for (const FaultGroupStats& g : s.faults) {
        if (g.case_number != 0 || g.strategy != st.name) continue;
        runs += g.runs;
        goals += g.goals_met;
        ok += g.successes;
        isolated += g.isolated;
        wrong += g.wrong;
      }
      if (runs == 0) continue;
      md << "- `" << st.name << "`: both SPEC §7 goals in " << goals << " / " << runs << " ("
         << fmt("%.1f", 100.0 * goals / runs) << " %), success in " << ok << " / " << runs << " ("
         << fmt("%.1f", 100.0 * ok / runs) << " %); isolated " << isolated << ", wrong " << wrong
         << ".\n";
    }
    bool unforced = false;
    for (const FaultGroupStats& g : s.faults) unforced = unforced || g.kind != "stuck_on";
    if (unforced) {
      md << "\nStuck-off and degraded jets show only while they are commanded: the runs in which the "
            "flight never commanded the jet after onset (its half of the channel, its pod's valve "
            "open), and over the isolated runs the time it was commanded from onset to the "
            "confirmation (and the impulse asked of it meanwhile; u_max for one second is 200 N s in the "
            "study's cases), and that impulse as seconds of firing at u_max (the draw's true u_max), "
            "the seconds an on/off jet would have fired.\n\n| strategy | fault | onset (s) | runs | "
            "never commanded | isolated | commanded before isolation p50 / p95 / max (s) | impulse "
            "p50 / p95 (N s) | firing at u_max p50 / p95 / max (s) |\n"
            "|---|---|---:|---:|---:|---:|---|---|---|\n";
      for (const FaultGroupStats& g : s.faults) {
        if (g.case_number != 0 || g.kind == "stuck_on") continue;
        md << "| `" << g.strategy << "` | " << g.kind << " | " << fmt("%.0f", g.onset_s) << " | "
           << g.runs << " | " << g.not_commanded << " | " << g.isolated << " | "
           << nc(g.commanded_to_isolation_s.p50, "%.1f") << " / "
           << nc(g.commanded_to_isolation_s.p95, "%.1f") << " / "
           << nc(g.commanded_to_isolation_max_s, "%.1f") << " | "
           << nc(g.commanded_impulse_to_isolation_ns.p50, "%.0f") << " / "
           << nc(g.commanded_impulse_to_isolation_ns.p95, "%.0f") << " | "
           << nc(g.firing_to_isolation_s.p50, "%.2f") << " / "
           << nc(g.firing_to_isolation_s.p95, "%.2f") << " / "
           << nc(g.firing_to_isolation_max_s, "%.2f") << " |\n";
      }
      if (!spec.faults.case_numbers.empty()) {
        md << "\nPer case, the same firing at u_max before isolation: isolated / runs, p50 / max "
              "(s).\n\n| strategy | fault | onset (s) |";
        for (int c : spec.faults.case_numbers) md << " case " << c << " |";
        md << "\n|---|---|---:|";
        for (std::size_t c = 0; c < spec.faults.case_numbers.size(); ++c) md << "---|";
        md << "\n";
        for (const FaultGroupStats& g : s.faults) {
          if (g.case_number != 0 || g.kind == "stuck_on") continue;
          md << "| `" << g.strategy << "` | " << g.kind << " | " << fmt("%.0f", g.onset_s) << " |";
          for (const FaultGroupStats& h : s.faults) {
            if (h.case_number == 0 || h.strategy != g.strategy || h.kind != g.kind ||
                h.onset_s != g.onset_s) {
              continue;
            }
            md << " " << h.isolated << "/" << h.runs << " (" << nc(h.firing_to_isolation_s.p50, "%.2f")
               << " / " << nc(h.firing_to_isolation_max_s, "%.2f") << ") |";
          }
          md << "\n";
        }
      }
    }
    if (!spec.faults.case_numbers.empty()) {
      md << "\nPer case: isolated / runs (latency p50 s), the runs that met both goals, and the "
            "successes.\n\n| strategy | fault | "
            "onset (s) |";
      for (int c : spec.faults.case_numbers) md << " case " << c << " |";
      md << "\n|---|---|---:|";
      for (std::size_t c = 0; c < spec.faults.case_numbers.size(); ++c) md << "---|";
      md << "\n";
      for (const FaultGroupStats& g : s.faults) {
        if (g.case_number != 0) continue;
        md << "| `" << g.strategy << "` | " << g.kind << " | " << fmt("%.0f", g.onset_s) << " |";
        for (int c : spec.faults.case_numbers) {
          const FaultGroupStats* x = nullptr;
          for (const FaultGroupStats& h : s.faults) {
            if (h.case_number == c && h.strategy == g.strategy && h.kind == g.kind &&
                h.onset_s == g.onset_s) {
              x = &h;
            }
          }
          if (x == nullptr) {
            md << " — |";
          } else {
            md << " " << x->isolated << "/" << x->runs << " (" << nc(x->latency_s.p50, "%.1f")
               << "), " << x->goals_met << " goals, " << x->successes << " ok |";
          }
        }
        md << "\n";
      }
    }
    bool any_stuck_on = false;
    for (const FaultGroupStats& g : s.faults) {
      any_stuck_on = any_stuck_on || (g.kind == "stuck_on" && g.case_number != 0);
    }
    if (any_stuck_on) {
      md << "\nStuck-on jets per case, from onset: detected (the first window above the no-fault "
            "bound at or after onset, or the first confirmation if it came first; over the runs "
            "that had one), the pod's latch valve closed and "
            "the jet isolated (over the isolated runs), p50 / p95 / max (s).\n\n| strategy | onset "
            "(s) | case | runs | detected | detection | valve closed | isolated | isolation |\n"
            "|---|---:|---:|---:|---:|---|---|---:|---|\n";
      auto three = [](const Percentiles& q, const std::optional<double>& mx) {
        return nc(q.p50, "%.1f") + " / " + nc(q.p95, "%.1f") + " / " + nc(mx, "%.1f");
      };
      for (const FaultGroupStats& g : s.faults) {
        if (g.kind != "stuck_on" || g.case_number == 0) continue;
        md << "| `" << g.strategy << "` | " << fmt("%.0f", g.onset_s) << " | " << g.case_number
           << " | " << g.runs << " | " << g.detected << " | " << three(g.detection_s, g.detection_max_s)
           << " | " << three(g.valve_s, g.valve_max_s) << " | " << g.isolated << " | "
           << three(g.latency_s, g.latency_max_s) << " |\n";
      }
    }
    if (!s.references.empty()) {
      md << "\nFault-free references (each case as the draws fly it, without the fault):\n\n"
            "| case | strategy | status | success | fuel (kg) |\n|---:|---|---|---|---:|\n";
      for (const ReferenceRow& r : s.references) {
        md << "| " << r.case_number << " | `" << r.strategy << "` | " << r.status << " | "
           << (r.success ? "yes" : "no") << " | " << nc(r.fuel_kg, "%.2f") << " |\n";
      }
    }
  }
  md << "\n## Worst draws\n\n";
  for (const StrategyStats& st : s.strategies) {
    md << "**`" << st.strategy << "`**\n\n";
    for (const WorstDraw& w : st.worst) {
      md << "- draw " << w.draw << ": " << w.why << " — `" << reproduce << " --draw " << w.draw
         << "`\n";
    }
    md << "\n";
  }
  md << "## Paired fuel differences (same draws)\n\n| a | b | n | mean a−b (kg) | p5/p50/p95 a−b "
        "(kg) | "
        "a uses less |\n|---|---|---:|---:|---|---:|\n";
  for (const PairedStats& q : s.paired) {
    md << "| `" << q.a << "` | `" << q.b << "` | " << q.n << " | " << fmt("%.2f", q.mean_diff_kg)
       << " | " << nc(q.diff.p5, "%.2f") << " / " << nc(q.diff.p50, "%.2f") << " / "
       << nc(q.diff.p95, "%.2f") << " | " << fmt("%.0f", 100.0 * q.frac_a_less) << " % |\n";
  }
  if (!s.crossovers.empty()) {
    md << "\n## Fuel-optimal against D+PD-based reference vs ‖ΔJ‖ (Proposition 5)\n\n";
    for (const Crossover& c : s.crossovers) {
      md << "`" << c.a << "` − `" << c.b << "`, median fuel difference per ‖ΔJ‖ bin: ";
      md << (c.crossover_kg_m2 ? "crossover at ‖ΔJ‖ ≈ " + fmt("%.3g", *c.crossover_kg_m2) + " kg m²"
                               : std::string("no crossover in the range"))
         << "\n\n| ‖ΔJ‖ bin (kg m²) | n | median Δfuel (kg) |\n|---|---:|---:|\n";
      for (std::size_t i = 0; i < c.bin_n.size(); ++i) {
        const double m = c.bin_median_diff[i];
        md << "| " << fmt("%.3g", c.bin_lo[i]) << "–" << fmt("%.3g", c.bin_hi[i]) << " | "
           << c.bin_n[i] << " | " << (std::isnan(m) ? std::string("—") : fmt("%.2f", m)) << " |\n";
      }
      md << "\n";
    }
  }
  if (!p.plots.empty()) {
    md << "\n## Plots\n\n";
    for (const std::string& f : p.plots) {
      md << "![" << fs::path(f).stem().string() << "](plots/" << fs::path(f).filename().string()
         << ")\n";
    }
  }
  md << "\n## Throughput\n\nSimulated " << fmt("%.4g", s.simulated_s) << " s in "
     << fmt("%.1f", s.closed_loop_wall_s_sum) << " s of closed-loop worker time ("
     << fmt("%.4g", s.closed_loop_wall_s_sum > 0 ? s.simulated_s / s.closed_loop_wall_s_sum : 0.0)
     << " simulated s per worker s); planning " << fmt("%.1f", s.plan_wall_s_sum) << " s.\n";
  return p;
}

}  // namespace rocksteady::dispersion
