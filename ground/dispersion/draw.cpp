#include "ground/dispersion/draw.hpp"

#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "ground/campaign/estimation_report.hpp"
#include "ground/campaign/fsw_flight_side.hpp"
#include "ground/plant/plant.hpp"

namespace rocksteady::dispersion {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

double spectral_norm(const Mat3& m) {
  const Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (m + m.transpose()), Eigen::EigenvaluesOnly);
  return es.eigenvalues().cwiseAbs().maxCoeff();
}

json vec(const Vec3& v) {
  return json::array({v(0), v(1), v(2)});
}
json mat(const Mat3& m) {
  return json::array({vec(m.row(0)), vec(m.row(1)), vec(m.row(2))});
}
Vec3 to_vec(const json& j) {
  return Vec3(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>());
}
Mat3 to_mat(const json& j) {
  Mat3 m;
  for (int r = 0; r < 3; ++r) m.row(r) = to_vec(j.at(static_cast<std::size_t>(r))).transpose();
  return m;
}
json opt(const std::optional<double>& v) {
  return v ? json(*v) : json(nullptr);
}
std::optional<double> to_opt(const json& j) {
  if (j.is_null()) return std::nullopt;
  return j.get<double>();
}

StrategyOutcome outcome_of(const campaign::RunResult& r, double eps_trans) {
  StrategyOutcome o;
  o.strategy = r.strategy;
  switch (r.status) {
    case campaign::RunStatus::kOk:
      o.status = "ok";
      break;
    case campaign::RunStatus::kNoReference:
      o.status = "no_plan";
      break;
    case campaign::RunStatus::kError:
      o.status = "error";
      break;
  }
  o.note = r.note;
  if (r.status == campaign::RunStatus::kOk) {
    o.t_omega_conv_s = r.t_omega_conv_s;
    o.fuel_at_t_omega_kg = r.fuel_at_t_omega_kg;
    o.t_q_conv_s = r.t_q_conv_s;
    o.fuel_at_t_q_kg = r.fuel_at_t_q_kg;
    o.total_fuel_kg = r.total_fuel_kg;
    o.success =
        r.t_omega_conv_s.has_value() && r.t_q_conv_s.has_value() && r.max_rate_rad_s <= eps_trans;
  }
  o.fuel_hat_kg = r.fuel_hat_kg;
  o.max_rate_rad_s = r.max_rate_rad_s;
  o.final_rate_rad_s = r.final_rate_rad_s;
  o.final_q_error = r.final_q_error;
  o.final_mode = r.final_mode;
  o.replan = r.replan;
  o.ticks = r.ticks;
  o.clipped_ticks = r.clipped_ticks;
  o.saturated_ticks = r.saturated_ticks;
  o.sim_s = r.sim_s;
  o.wall_s = r.wall_s;
  o.estimation = r.estimation;
  o.fdi = r.fdi;
  return o;
}

}  // namespace

Readback read_back(const plant::Plant& plant, const gnc::GncParams& flown) {
  const plant::PlantParams& t = plant.params();
  Readback b;
  b.delta_j = t.mass.j_ast - flown.mass_hat.j_ast;
  b.delta_j_norm = spectral_norm(b.delta_j);
  b.delta_r = t.mass.r_so_bcm - flown.mass_hat.r_so_bcm;
  b.delta_r_norm = b.delta_r.norm();
  b.omega0 = plant.omega();
  b.mrp0 = plant.mrp();
  b.gyro_psd = t.sensors.gyro_psd;
  b.star_psd = t.sensors.star_psd;
  b.disturbance_sigma_nm = t.disturbance.sigma_nm;
  b.noise_seed = t.seed;
  b.u_max_true_n = t.rcs.u_max;
  b.u_max_flight_n = flown.rcs.u_max;
  b.allocator = flown.allocator == gnc::AllocatorKind::kL1 ? "l1" : "pinv";
  b.faults = plant::describe(plant.params().faults);
  return b;
}

namespace {

// The draw's thruster fault added to the plant's (replacing a case file's fault of that thruster).
void add_fault(const DrawParams& d, config::RunSetup& s, const std::string& file) {
  if (!d.has_fault) return;
  auto& faults = s.truth.faults;
  for (auto it = faults.begin(); it != faults.end();) {
    it = it->thruster == d.fault.thruster ? faults.erase(it) : it + 1;
  }
  faults.push_back(d.fault);
  try {
    plant::validate(s.truth);
  } catch (const std::invalid_argument& e) {
    throw config::ConfigError(file, "faults", e.what());
  }
}

}  // namespace

config::RunSetup make_setup(const config::MissionConfig& mission, const config::GncConfig& gnc,
                            const DispersionSpec& spec, const DrawParams& d) {
  if (!d.case_file.empty()) {  // a fault dispersion over study cases: the case as `campaign` flies it
    config::RunSetup s = config::load_case_run(mission, gnc, d.case_file);
    s.case_name = "draw" + std::to_string(d.index);
    s.duration_s = spec.duration_s;
    if (spec.override_allocator) s.flight.allocator = spec.allocator;
    add_fault(d, s, spec.file);
    return s;
  }
  config::MissionConfig m = mission;
  m.initial_mrp = d.mrp0;
  m.initial_omega = d.omega0;
  m.disturbance_sigma_nm = d.disturbance_sigma_nm;
  config::CaseConfig c;
  c.file = spec.file + " draw " + std::to_string(d.index);
  c.number = d.index;
  c.description = spec.name + " draw " + std::to_string(d.index);
  c.delta_j_norm = 0.0;  // the draw's errors are applied below (a full matrix, any direction)
  c.delta_r_norm = 0.0;
  c.gyro_psd = d.gyro_psd;
  c.star_psd = d.star_psd;
  c.u_max = d.u_max_n;
  c.duration_s = spec.duration_s;
  c.seed = d.noise_seed;
  config::RunSetup s = config::assemble(m, gnc, c);
  s.truth.thruster_strength = d.thruster_strength;
  s.truth.sensors.gyro_bias = d.gyro_bias;
  s.case_name = "draw" + std::to_string(d.index);
  // Estimates, Eq. (6): estimate = true - error.
  s.flight.mass_hat.j_ast = mission.mass.j_ast - d.delta_j;
  s.flight.mass_hat.r_so_bcm = mission.mass.r_so_bcm - d.delta_r;
  s.mass_hat = s.flight.mass_hat;
  if (spec.override_allocator) s.flight.allocator = spec.allocator;
  const gnc::ParamCheck check = gnc::validate(s.flight);
  if (!check.ok) throw config::ConfigError(c.file, check.field, check.reason);
  add_fault(d, s, spec.file);
  return s;
}

namespace {

DrawResult fly_sampled(const config::MissionConfig& mission, const config::GncConfig& gnc,
                       const DispersionSpec& spec, int index, const DrawParams& sampled,
                       campaign::TrajectorySource& planner, const FlyOptions& options) {
  const auto wall0 = std::chrono::steady_clock::now();
  DrawResult r;
  r.index = index;
  r.sampled = sampled;
  auto fail_all = [&](const std::string& status, const std::string& why) {
    for (const campaign::Strategy& st : spec.strategies) {
      StrategyOutcome o;
      o.strategy = st.name;
      o.status = status;
      o.note = why;
      r.runs.push_back(o);
    }
  };
  if (!r.sampled.error.empty()) {
    fail_all("error", r.sampled.error);
    return r;
  }
  config::RunSetup setup;
  try {
    setup = make_setup(mission, gnc, spec, r.sampled);
  } catch (const std::exception& e) {
    fail_all("error", e.what());
    return r;
  }
  r.eps_trans_rad_s = setup.flight.guidance.eps_trans;

  // One plan per draw and horizon (the draw's estimated model and first rate measurement), shared.
  std::shared_ptr<const gnc::TrajectoryTable> plans[campaign::kPlanHorizons];
  std::string notes[campaign::kPlanHorizons];
  bool used[campaign::kPlanHorizons] = {false, false};
  for (const campaign::Strategy& st : spec.strategies) {
    if (st.needs_trajectory()) used[static_cast<int>(st.horizon)] = true;
  }
  for (int h = 0; h < campaign::kPlanHorizons; ++h) {
    if (!used[h]) continue;
    r.planned = true;
    campaign::PlanRequest req;
    req.setup = &setup;
    req.model = setup.flight;
    req.study_horizon = h == static_cast<int>(campaign::PlanHorizon::kStudy);
    plant::Plant probe(setup.truth);
    req.omega_init = probe.read_sensors().gyro.rate;
    const campaign::PlanOutcome o = planner.plan(req);
    plans[h] = o.table;
    notes[h] = o.note;
    const bool first = h == 0 || !used[0];  // the first horizon planned
    r.have_plan = (first || r.have_plan) && plans[h] != nullptr;
    if (r.plan_note.empty() || plans[h] == nullptr) r.plan_note = o.note;
    r.plan_wall_s += o.wall_s;
  }

  for (const campaign::Strategy& st : spec.strategies) {
    campaign::RunResult run;
    try {
      campaign::FswFlightSide flight;
      campaign::RunOptions opt;
      opt.duration_s = spec.duration_s;
      opt.log_interval_s = options.log_interval_s;
      opt.replan = spec.replan;
      Readback seen;
      bool have = false;
      opt.on_start = [&](const plant::Plant& p) {
        seen = read_back(p, flight.computer().app().active_params());
        have = true;
      };
      const int h = static_cast<int>(st.horizon);
      const gnc::TrajectoryTable* traj = st.needs_trajectory() ? plans[h].get() : nullptr;
      run = campaign::run_closed_loop(setup, st, flight, traj, opt, notes[h]);
      if (have && !r.flown) r.flown = seen;
    } catch (const std::exception& e) {
      run.strategy = st.name;
      run.status = campaign::RunStatus::kError;
      run.note = e.what();
    }
    StrategyOutcome o = outcome_of(run, r.eps_trans_rad_s);
    if (st.needs_trajectory() && run.status == campaign::RunStatus::kOk && o.note.empty()) {
      o.note = notes[static_cast<int>(st.horizon)];
    }
    r.runs.push_back(o);
    if (options.full_runs != nullptr) options.full_runs->push_back(std::move(run));
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

}  // namespace

DrawResult fly_draw(const config::MissionConfig& mission, const config::GncConfig& gnc,
                    const DispersionSpec& spec, const Sampler& sampler, int index,
                    campaign::TrajectorySource& planner, const FlyOptions& options) {
  return fly_sampled(mission, gnc, spec, index, sampler.draw(index), planner, options);
}

std::optional<DrawParams> reference_params(const DispersionSpec& spec, const Sampler& sampler,
                                           std::size_t case_index) {
  const FaultPlan& fp = spec.faults;
  if (!fp.enabled || case_index >= fp.case_files.size()) return std::nullopt;
  for (int i = 0; i < spec.draws; ++i) {
    DrawParams d = sampler.draw(i);
    if (d.case_file != fp.case_files[case_index]) continue;
    d.index = -1;
    d.has_fault = false;
    d.fault = plant::ThrusterFault{};
    return d;
  }
  return std::nullopt;
}

DrawResult fly_reference(const config::MissionConfig& mission, const config::GncConfig& gnc,
                         const DispersionSpec& spec, const DrawParams& reference,
                         campaign::TrajectorySource& planner) {
  return fly_sampled(mission, gnc, spec, -1, reference, planner, FlyOptions{});
}

std::string reference_path(const std::string& dir, int case_number) {
  return (fs::path(dir) / "reference" / ("case" + std::to_string(case_number) + ".json")).string();
}

DrawResult crashed_draw(const DispersionSpec& spec, const Sampler& sampler, int index,
                        const std::string& reason) {
  DrawResult r;
  r.index = index;
  r.sampled = sampler.draw(index);
  for (const campaign::Strategy& st : spec.strategies) {
    StrategyOutcome o;
    o.strategy = st.name;
    o.status = "crashed";
    o.note = reason;
    r.runs.push_back(o);
  }
  return r;
}

json to_json(const DrawResult& r, bool with_timing) {
  const DrawParams& d = r.sampled;
  json sampled = {{"seed", d.seed},
                  {"u", d.u},
                  {"delta_j_ast_norm_kg_m2", d.delta_j_norm},
                  {"delta_j_ast_kg_m2", mat(d.delta_j)},
                  {"pd_redraws", d.pd_redraws},
                  {"delta_r_so_bcm_norm_m", d.delta_r_norm},
                  {"delta_r_so_bcm_m", vec(d.delta_r)},
                  {"initial_rate_norm_rad_s", d.initial_rate_norm},
                  {"omega0_rad_s", vec(d.omega0)},
                  {"mrp0", vec(d.mrp0)},
                  {"gyro_noise_psd_rad2_s2", d.gyro_psd},
                  {"star_noise_psd", d.star_psd},
                  {"disturbance_sigma_nm", d.disturbance_sigma_nm},
                  {"noise_seed", d.noise_seed},
                  {"u_max_n", d.u_max_n},
                  {"thruster_strength",
                   std::vector<double>(d.thruster_strength.data(),
                                       d.thruster_strength.data() + gnc::kThrusters)},
                  {"gyro_bias_rad_s", vec(d.gyro_bias)},
                  {"case_file", d.case_file},
                  {"case", d.case_number},
                  {"fault", d.has_fault ? plant::describe(d.fault) : std::string("none")},
                  {"error", d.error}};
  if (d.has_fault) {
    sampled["fault_thruster"] = d.fault.thruster;
    sampled["fault_kind"] = plant::to_string(d.fault.kind);
    sampled["fault_onset_s"] = d.fault.onset_s;
    sampled["fault_factor"] = d.fault.factor;
  }
  json flown = nullptr;
  if (r.flown) {
    const Readback& b = *r.flown;
    flown = {{"delta_j_ast_kg_m2", mat(b.delta_j)},
             {"delta_j_ast_norm_kg_m2", b.delta_j_norm},
             {"delta_r_so_bcm_m", vec(b.delta_r)},
             {"delta_r_so_bcm_norm_m", b.delta_r_norm},
             {"omega0_rad_s", vec(b.omega0)},
             {"mrp0", vec(b.mrp0)},
             {"gyro_noise_psd_rad2_s2", b.gyro_psd},
             {"star_noise_psd", b.star_psd},
             {"disturbance_sigma_nm", b.disturbance_sigma_nm},
             {"noise_seed", b.noise_seed},
             {"u_max_true_n", b.u_max_true_n},
             {"u_max_flight_n", b.u_max_flight_n},
             {"allocator", b.allocator},
             {"faults", b.faults}};
  }
  json runs = json::array();
  json run_wall = json::object();
  for (const StrategyOutcome& o : r.runs) {
    json run = {{"strategy", o.strategy},
                {"status", o.status},
                {"note", o.note},
                {"success", o.success},
                {"t_omega_conv_s", opt(o.t_omega_conv_s)},
                {"fuel_at_t_omega_kg", opt(o.fuel_at_t_omega_kg)},
                {"t_q_conv_s", opt(o.t_q_conv_s)},
                {"fuel_at_t_q_kg", opt(o.fuel_at_t_q_kg)},
                {"total_fuel_kg", opt(o.total_fuel_kg)},
                {"fuel_estimate_kg", o.fuel_hat_kg},
                {"max_rate_rad_s", o.max_rate_rad_s},
                {"final_rate_rad_s", o.final_rate_rad_s},
                {"final_q_error", o.final_q_error},
                {"final_mode", o.final_mode},
                {"ticks", o.ticks},
                {"plant_clipped_ticks", o.clipped_ticks},
                {"allocator_saturated_ticks", o.saturated_ticks},
                {"simulated_s", o.sim_s},
                {"estimation", campaign::estimation_json(o.estimation)},
                {"fdi", campaign::fdi_json(o.fdi)}};
    // The plans of a replan strategy, without their solve wall times (the result is reproducible).
    if (o.replan.enabled) run["replan"] = campaign::replan_json(o.replan, false);
    runs.push_back(std::move(run));
    run_wall[o.strategy] = o.wall_s;
  }
  json out = {{"result",
               {{"draw", r.index},
                {"sampled", sampled},
                {"flown", flown},
                {"eps_trans_rad_s", r.eps_trans_rad_s},
                {"planned", r.planned},
                {"have_plan", r.have_plan},
                {"plan_note", r.plan_note},
                {"runs", runs}}}};
  if (with_timing) {
    out["timing"] = {
        {"draw_wall_s", r.wall_s}, {"plan_wall_s", r.plan_wall_s}, {"run_wall_s", run_wall}};
  }
  return out;
}

DrawResult draw_from_json(const json& top) {
  const json& j = top.at("result");
  DrawResult r;
  r.index = j.at("draw").get<int>();
  const json& s = j.at("sampled");
  DrawParams& d = r.sampled;
  d.index = r.index;
  d.seed = s.at("seed").get<std::uint64_t>();
  d.u = s.at("u").get<std::vector<double>>();
  d.delta_j_norm = s.at("delta_j_ast_norm_kg_m2").get<double>();
  d.delta_j = to_mat(s.at("delta_j_ast_kg_m2"));
  d.pd_redraws = s.at("pd_redraws").get<int>();
  d.delta_r_norm = s.at("delta_r_so_bcm_norm_m").get<double>();
  d.delta_r = to_vec(s.at("delta_r_so_bcm_m"));
  d.initial_rate_norm = s.at("initial_rate_norm_rad_s").get<double>();
  d.omega0 = to_vec(s.at("omega0_rad_s"));
  d.mrp0 = to_vec(s.at("mrp0"));
  d.gyro_psd = s.at("gyro_noise_psd_rad2_s2").get<double>();
  d.star_psd = s.at("star_noise_psd").get<double>();
  d.disturbance_sigma_nm = s.at("disturbance_sigma_nm").get<double>();
  d.noise_seed = s.at("noise_seed").get<std::uint64_t>();
  d.u_max_n = s.at("u_max_n").get<double>();
  if (s.contains("thruster_strength")) {
    const auto& k = s.at("thruster_strength");
    for (int i = 0; i < gnc::kThrusters; ++i) {
      d.thruster_strength(i) = k.at(static_cast<std::size_t>(i)).get<double>();
    }
  }
  if (s.contains("gyro_bias_rad_s")) d.gyro_bias = to_vec(s.at("gyro_bias_rad_s"));
  d.error = s.at("error").get<std::string>();
  d.case_file = s.value("case_file", "");
  d.case_number = s.value("case", 0);
  if (s.contains("fault_thruster")) {
    d.has_fault = true;
    d.fault.thruster = s.at("fault_thruster").get<int>();
    plant::parse_fault_kind(s.at("fault_kind").get<std::string>(), d.fault.kind);
    d.fault.onset_s = s.at("fault_onset_s").get<double>();
    d.fault.factor = s.at("fault_factor").get<double>();
  }
  const json& f = j.at("flown");
  if (!f.is_null()) {
    Readback b;
    b.delta_j = to_mat(f.at("delta_j_ast_kg_m2"));
    b.delta_j_norm = f.at("delta_j_ast_norm_kg_m2").get<double>();
    b.delta_r = to_vec(f.at("delta_r_so_bcm_m"));
    b.delta_r_norm = f.at("delta_r_so_bcm_norm_m").get<double>();
    b.omega0 = to_vec(f.at("omega0_rad_s"));
    b.mrp0 = to_vec(f.at("mrp0"));
    b.gyro_psd = f.at("gyro_noise_psd_rad2_s2").get<double>();
    b.star_psd = f.at("star_noise_psd").get<double>();
    b.disturbance_sigma_nm = f.at("disturbance_sigma_nm").get<double>();
    b.noise_seed = f.at("noise_seed").get<std::uint64_t>();
    b.u_max_true_n = f.at("u_max_true_n").get<double>();
    b.u_max_flight_n = f.at("u_max_flight_n").get<double>();
    b.allocator = f.value("allocator", "");
    b.faults = f.value("faults", "none");
    r.flown = b;
  }
  r.eps_trans_rad_s = j.at("eps_trans_rad_s").get<double>();
  r.planned = j.at("planned").get<bool>();
  r.have_plan = j.at("have_plan").get<bool>();
  r.plan_note = j.at("plan_note").get<std::string>();
  const json* timing = top.contains("timing") ? &top.at("timing") : nullptr;
  for (const json& o : j.at("runs")) {
    StrategyOutcome x;
    x.strategy = o.at("strategy").get<std::string>();
    x.status = o.at("status").get<std::string>();
    x.note = o.at("note").get<std::string>();
    x.success = o.at("success").get<bool>();
    x.t_omega_conv_s = to_opt(o.at("t_omega_conv_s"));
    x.fuel_at_t_omega_kg = to_opt(o.at("fuel_at_t_omega_kg"));
    x.t_q_conv_s = to_opt(o.at("t_q_conv_s"));
    x.fuel_at_t_q_kg = to_opt(o.at("fuel_at_t_q_kg"));
    x.total_fuel_kg = to_opt(o.at("total_fuel_kg"));
    x.fuel_hat_kg = o.at("fuel_estimate_kg").get<double>();
    x.max_rate_rad_s = o.at("max_rate_rad_s").get<double>();
    x.final_rate_rad_s = o.at("final_rate_rad_s").get<double>();
    x.final_q_error = o.at("final_q_error").get<double>();
    x.final_mode = o.at("final_mode").get<std::string>();
    x.ticks = o.at("ticks").get<std::uint64_t>();
    x.clipped_ticks = o.at("plant_clipped_ticks").get<std::uint64_t>();
    x.saturated_ticks = o.at("allocator_saturated_ticks").get<std::uint64_t>();
    x.sim_s = o.at("simulated_s").get<double>();
    if (o.contains("estimation")) x.estimation = campaign::estimation_from_json(o.at("estimation"));
    if (o.contains("fdi")) x.fdi = campaign::fdi_from_json(o.at("fdi"));
    if (o.contains("replan")) x.replan = campaign::replan_from_json(o.at("replan"));
    if (timing != nullptr && timing->at("run_wall_s").contains(x.strategy)) {
      x.wall_s = timing->at("run_wall_s").at(x.strategy).get<double>();
    }
    r.runs.push_back(x);
  }
  if (timing != nullptr) {
    r.wall_s = timing->at("draw_wall_s").get<double>();
    r.plan_wall_s = timing->at("plan_wall_s").get<double>();
  }
  return r;
}

std::string draw_path(const std::string& dir, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d.json", index);
  return (fs::path(dir) / "draws" / name).string();
}

namespace {

void write_atomically(const std::string& path, const DrawResult& r) {
  fs::create_directories(fs::path(path).parent_path());
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error("cannot write " + tmp);
    out << to_json(r).dump(1) << "\n";
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  fs::rename(tmp, path);  // atomic: a reader sees the whole file or none
}

std::optional<DrawResult> read_result(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    const json j = json::parse(in);
    return draw_from_json(j);
  } catch (const std::exception&) {
    return std::nullopt;  // unreadable: run again
  }
}

}  // namespace

void write_draw(const std::string& dir, const DrawResult& r) {
  write_atomically(draw_path(dir, r.index), r);
}

std::optional<DrawResult> read_draw(const std::string& dir, int index) {
  return read_result(draw_path(dir, index));
}

void write_reference(const std::string& dir, const DrawResult& r) {
  write_atomically(reference_path(dir, r.sampled.case_number), r);
}

std::optional<DrawResult> read_reference(const std::string& dir, int case_number) {
  return read_result(reference_path(dir, case_number));
}

}  // namespace rocksteady::dispersion
