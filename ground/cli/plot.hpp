// rocksteady-ground plot: the study's Figure-3 plot of any run — true body rate, attitude and fuel,
// with the flight's estimate and reference when the input has them — from a PIL LCM log
// (RS_PLANT_TRUTH, RS_GNC_TLM) or a CSV with named columns (the campaign's timeseries.csv, the
// plant's --out CSV). The convergence times of SPEC §7 are computed from the true state and marked,
// or annotated NC. Panels share one x axis with fixed margins (aligned), the y ranges are padded
// (nothing clipped at the frame), and truth, estimate and reference differ in colour and dash.
// gnuplot draws it (pngcairo).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace rocksteady::ground::cli {

struct PlotRow {
  double t{0.0};
  std::array<double, 3> value{};
};

// What a run's plot shows; an empty series is left out.
struct PlotData {
  std::string title;
  std::vector<PlotRow> omega, omega_hat, omega_r;         // rad/s
  std::vector<PlotRow> q, q_hat, q_d;                     // MRP
  std::vector<std::pair<double, double>> fuel, fuel_hat;  // kg
  std::optional<std::array<double, 3>> q_final;           // from telemetry (q_hat - attitude_error)
};

// Reads an LCM log or a CSV (by its first bytes). Throws std::runtime_error naming the file and the
// reason (unreadable, no usable channel or columns).
PlotData load_plot_data(const std::string& path);

struct Convergence {
  std::optional<double> t_omega;  // SPEC §7: least t after which |omega| <= omega_tol for good
  std::optional<double> t_q;      //          least t after which |q - q_final| <= q_tol for good
};
Convergence convergence(const PlotData& d, const std::array<double, 3>& q_final,
                        double omega_tol = 1e-4, double q_tol = 1e-2);

struct PlotOptions {
  std::string output;                            // PNG path
  std::optional<std::array<double, 3>> q_final;  // default: the telemetry's, else 0
  int width{1100}, height{1100};
};

// Writes OUTPUT's data (.csv) and gnuplot script (.gp) beside it and runs gnuplot. Returns "" on
// success, else the error.
std::string write_plot(const PlotData& d, const PlotOptions& options);

}  // namespace rocksteady::ground::cli
