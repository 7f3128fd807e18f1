#include "ground/cli/plot.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "ground/dictionary/dictionary.hpp"

namespace rocksteady::ground::cli {

namespace fs = std::filesystem;

namespace {

bool is_lcm_log(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char magic[4] = {0, 0, 0, 0};
  in.read(reinterpret_cast<char*>(magic), 4);
  return in.gcount() == 4 && magic[0] == 0xED && magic[1] == 0xA1 && magic[2] == 0xDA &&
         magic[3] == 0x01;
}

// The values of points `prefix_0..2` of a decoded message.
std::array<double, 3> vec3(const dictionary::Channel& c, const std::vector<double>& v,
                           const std::string& prefix) {
  std::array<double, 3> out{};
  for (int i = 0; i < 3; ++i) {
    out[static_cast<std::size_t>(i)] =
        v[static_cast<std::size_t>(dictionary::find_point(c, prefix + "_" + std::to_string(i)))];
  }
  return out;
}

double scalar(const dictionary::Channel& c, const std::vector<double>& v, const char* key) {
  return v[static_cast<std::size_t>(dictionary::find_point(c, key))];
}

PlotData load_log(const std::string& path) {
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error(path + ": cannot open as an LCM log");
  const dictionary::Channel* truth = dictionary::find_channel("RS_PLANT_TRUTH");
  const dictionary::Channel* tlm = dictionary::find_channel("RS_GNC_TLM");
  PlotData d;
  std::vector<double> v;
  std::string text;
  wire::DecodeStatus st{};
  for (const lcm::LogEvent* ev = log.readNextEvent(); ev != nullptr; ev = log.readNextEvent()) {
    const dictionary::Channel* c = ev->channel == truth->channel ? truth
                                   : ev->channel == tlm->channel ? tlm
                                                                 : nullptr;
    if (c == nullptr) continue;
    v.assign(static_cast<std::size_t>(c->point_count), 0.0);
    if (!c->decode(ev->data, ev->datalen, v.data(), text, st)) continue;
    const double t = scalar(*c, v, "t");
    if (c == truth) {
      d.omega.push_back({t, vec3(*c, v, "omega")});
      d.q.push_back({t, vec3(*c, v, "q")});
      d.fuel.emplace_back(t, scalar(*c, v, "fuel_used_kg"));
    } else {
      d.omega_hat.push_back({t, vec3(*c, v, "omega_hat")});
      d.omega_r.push_back({t, vec3(*c, v, "omega_r")});
      d.q_hat.push_back({t, vec3(*c, v, "q_hat")});
      d.q_d.push_back({t, vec3(*c, v, "q_d")});
      d.fuel_hat.emplace_back(t, scalar(*c, v, "fuel_kg"));
      const auto qh = vec3(*c, v, "q_hat");
      const auto e = vec3(*c, v, "attitude_error");
      d.q_final = std::array<double, 3>{qh[0] - e[0], qh[1] - e[1], qh[2] - e[2]};
    }
  }
  if (d.omega.empty() && d.omega_hat.empty()) {
    throw std::runtime_error(path + ": no RS_PLANT_TRUTH or RS_GNC_TLM messages to plot");
  }
  return d;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');) out.push_back(cell);
  return out;
}

PlotData load_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read file");
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ": empty file");
  std::map<std::string, std::size_t> col;
  const std::vector<std::string> header = split(line);
  for (std::size_t i = 0; i < header.size(); ++i) col[header[i]] = i;
  const auto has3 = [&](const std::string& p) {
    return col.count(p + "_x") && col.count(p + "_y") && col.count(p + "_z");
  };
  const std::string t_key = col.count("t_s") ? "t_s" : "t";
  if (!col.count(t_key) || !has3("omega")) {
    throw std::runtime_error(path +
                             ": not a run CSV (needs columns t_s and omega_x, omega_y, omega_z)");
  }
  PlotData d;
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    const std::vector<std::string> cells = split(line);
    const auto num = [&](const std::string& key) {
      const std::size_t i = col.at(key);
      char* end = nullptr;
      const double v = i < cells.size() ? std::strtod(cells[i].c_str(), &end) : std::nan("");
      if (i >= cells.size() || end == cells[i].c_str()) {
        throw std::runtime_error(path + ":" + std::to_string(line_no) + ": column " + key +
                                 " is not a number");
      }
      return v;
    };
    const auto v3 = [&](const std::string& p) {
      return std::array<double, 3>{num(p + "_x"), num(p + "_y"), num(p + "_z")};
    };
    const double t = num(t_key);
    d.omega.push_back({t, v3("omega")});
    if (has3("omega_hat")) d.omega_hat.push_back({t, v3("omega_hat")});
    if (has3("q")) d.q.push_back({t, v3("q")});
    if (has3("q_hat")) d.q_hat.push_back({t, v3("q_hat")});
    if (col.count("fuel_kg")) d.fuel.emplace_back(t, num("fuel_kg"));
    if (col.count("fuel_hat_kg")) d.fuel_hat.emplace_back(t, num("fuel_hat_kg"));
  }
  if (d.omega.empty()) throw std::runtime_error(path + ": no rows");
  return d;
}

double norm3(const std::array<double, 3>& v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

// The least t after which pred holds for every later sample (SPEC §7), or nullopt.
template <class F>
std::optional<double> converged_from(const std::vector<PlotRow>& rows, F pred) {
  std::optional<double> t;
  for (const PlotRow& r : rows) {
    if (!pred(r.value)) {
      t.reset();
    } else if (!t) {
      t = r.t;
    }
  }
  return t;
}

}  // namespace

PlotData load_plot_data(const std::string& path) {
  if (!fs::exists(path)) throw std::runtime_error(path + ": no such file");
  PlotData d = is_lcm_log(path) ? load_log(path) : load_csv(path);
  d.title = fs::path(path).filename().string();
  return d;
}

Convergence convergence(const PlotData& d, const std::array<double, 3>& q_final, double omega_tol,
                        double q_tol) {
  Convergence c;
  c.t_omega = converged_from(d.omega,
                             [&](const std::array<double, 3>& w) { return norm3(w) <= omega_tol; });
  c.t_q = converged_from(d.q, [&](const std::array<double, 3>& q) {
    return norm3({q[0] - q_final[0], q[1] - q_final[1], q[2] - q_final[2]}) <= q_tol;
  });
  return c;
}

std::string write_plot(const PlotData& d, const PlotOptions& o) {
  const fs::path png(o.output);
  const fs::path dat = fs::path(o.output).replace_extension(".dat");
  const fs::path gp = fs::path(o.output).replace_extension(".gp");
  const std::array<double, 3> q_final =
      o.q_final ? *o.q_final : d.q_final.value_or(std::array<double, 3>{});
  const Convergence conv = convergence(d, q_final);

  // Data: one gnuplot index block per present series.
  std::ofstream out(dat);
  if (!out) return dat.string() + ": cannot write";
  out.precision(10);
  std::map<std::string, int> index;
  int next = 0;
  const auto block3 = [&](const char* name, const std::vector<PlotRow>& rows) {
    if (rows.empty()) return;
    out << "# " << name << ": t x y z\n";
    for (const PlotRow& r : rows)
      out << r.t << " " << r.value[0] << " " << r.value[1] << " " << r.value[2] << "\n";
    out << "\n\n";
    index[name] = next++;
  };
  const auto block1 = [&](const char* name, const std::vector<std::pair<double, double>>& rows) {
    if (rows.empty()) return;
    out << "# " << name << ": t value\n";
    for (const auto& [t, v] : rows) out << t << " " << v << "\n";
    out << "\n\n";
    index[name] = next++;
  };
  block3("omega", d.omega);
  block3("omega_hat", d.omega_hat);
  block3("omega_r", d.omega_r);
  block3("q", d.q);
  block3("q_hat", d.q_hat);
  block3("q_d", d.q_d);
  block1("fuel", d.fuel);
  block1("fuel_hat", d.fuel_hat);
  out.close();

  std::ofstream g(gp);
  if (!g) return gp.string() + ": cannot write";
  const std::string f = "'" + dat.filename().string() + "'";
  g << "# Rocksteady run plot (the study's Figure 3), generated by rocksteady-ground plot.\n"
    << "set terminal pngcairo size " << o.width << "," << o.height << " noenhanced font ',10'\n"
    << "set output '" << png.filename().string() << "'\n"
    << "set grid\n"
    << "set autoscale xfixmin\nset autoscale xfixmax\n"
    // Padded y ranges: no trace runs along the frame.
    << "set offsets 0, 0, graph 0.06, graph 0.06\n"
    << "set format y '%.3g'\n"
    << "set multiplot title '" << d.title
    << "'\n"
    // One left and right margin for every panel: the x axes line up.
    << "set lmargin at screen 0.10\nset rmargin at screen 0.78\n"
    << "set style line 1 lc rgb '#d62728' lw 2\nset style line 2 lc rgb '#2ca02c' lw 2\n"
    << "set style line 3 lc rgb '#1f77b4' lw 2\n";
  const char* axis[3] = {"x", "y", "z"};
  // Panel k of 3, top to bottom.
  const auto panel = [&](int k) {
    const double top = 0.95 - k * 0.30;
    g << "set tmargin at screen " << top << "\nset bmargin at screen " << top - 0.25 << "\n";
    // The key beside its panel, at the same place for every panel.
    g << "set key at screen 0.80, screen " << top
      << " left top vertical Left reverse spacing 1.1\n";
    if (k < 2) {
      g << "set format x ''\nunset xlabel\n";
    } else {
      g << "set format x '%g'\nset xlabel 't (s)'\n";
    }
  };
  int label = 1;
  const auto mark = [&](const std::optional<double>& t, const char* name, const char* color,
                        double y) {
    if (t) {
      g << "set arrow " << label << " from " << *t << ", graph 0 to " << *t
        << ", graph 1 nohead dt 2 lw 1.5 lc rgb '" << color << "'\n";
      // Left of the line: the label stays inside the frame even near the end of the run.
      g << "set label " << label << " '" << name << " = "
        << static_cast<long long>(std::llround(*t)) << " s' at " << *t << ", graph " << y
        << " right offset -0.5,0 tc rgb '" << color << "' front\n";
    } else {
      g << "set label " << label << " '" << name
        << ": NC (not converged in this run)' at graph 0.02, graph " << y << " tc rgb '" << color
        << "' front\n";
    }
    ++label;
  };
  const auto clear_marks = [&]() {
    g << "unset arrow\nunset label\n";
    label = 1;
  };
  const auto triple = [&](const char* sym, const char* truth, const char* est, const char* ref) {
    std::string cmd = "plot ";
    const char* sep = "";
    const auto add = [&](const char* name, const char* what, const char* dash, int lw) {
      if (!index.count(name)) return;
      for (int i = 0; i < 3; ++i) {
        cmd += std::string(sep) + f + " index " + std::to_string(index[name]) +
               " using 1:" + std::to_string(i + 2) + " with lines ls " + std::to_string(i + 1) +
               " dt " + dash + " lw " + std::to_string(lw) + " title '" + sym + "_" + axis[i] +
               " " + what + "'";
        sep = ", ";
      }
    };
    add(truth, "true", "1", 2);
    add(est, "estimate", "2", 1);
    add(ref, "reference", "3", 1);
    return cmd;
  };
  if (index.count("omega") || index.count("omega_hat")) {
    panel(0);
    mark(conv.t_omega, "t_omega,conv", "#d62728", 0.90);
    g << "set ylabel 'omega (rad/s)'\n" << triple("omega", "omega", "omega_hat", "omega_r") << "\n";
    clear_marks();
  }
  if (index.count("q") || index.count("q_hat")) {
    panel(1);
    mark(conv.t_q, "t_q,conv", "#1f77b4", 0.90);
    g << "set ylabel 'q (MRP)'\n" << triple("q", "q", "q_hat", "q_d") << "\n";
    clear_marks();
  }
  if (index.count("fuel") || index.count("fuel_hat")) {
    panel(2);
    std::string cmd = "plot ";
    if (index.count("fuel")) {
      cmd += f + " index " + std::to_string(index["fuel"]) +
             " using 1:2 with lines lc rgb 'black' lw 2 title 'fuel used, true'";
    }
    if (index.count("fuel_hat")) {
      cmd += std::string(index.count("fuel") ? ", " : "") + f + " index " +
             std::to_string(index["fuel_hat"]) +
             " using 1:2 with lines lc rgb '#ff7f0e' dt 2 lw 1.5 title 'fuel used, on-board'";
    }
    // Fuel starts at zero: pad only above.
    g << "set offsets 0, 0, graph 0.06, 0\nset yrange [0:*]\nset ylabel 'fuel (kg)'\n"
      << cmd << "\n";
  }
  g << "unset multiplot\n";
  g.close();

  const std::string dir = png.has_parent_path() ? png.parent_path().string() : ".";
  const std::string log = (fs::path(dir) / (png.stem().string() + ".gnuplot.log")).string();
  const std::string cmd = "cd '" + dir + "' && gnuplot '" + gp.filename().string() + "' > '" +
                          fs::path(log).filename().string() + "' 2>&1";
  if (std::system(cmd.c_str()) != 0) return "gnuplot failed (see " + log + ")";
  if (!fs::exists(png)) return "gnuplot wrote no " + png.string() + " (see " + log + ")";
  return "";
}

}  // namespace rocksteady::ground::cli
