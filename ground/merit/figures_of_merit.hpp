// The study's figures of merit (SPEC §7), computed on the TRUE state by every harness that flies
// the plant: the in-process campaign and the plant process (rocksteady-plant) alike.
#pragma once

#include <optional>

#include <Eigen/Core>

namespace rocksteady::merit {

// SPEC §7: the least time after which value(t) <= tol for all later t, and the fuel used by then.
class ConvergenceTracker {
 public:
  explicit ConvergenceTracker(double tol) : tol_(tol) {}
  void add(double t, double value, double fuel_kg);
  bool converged() const { return have_ && last_ok_; }  // NC otherwise
  std::optional<double> time() const;
  std::optional<double> fuel_kg() const;

 private:
  double tol_;
  bool have_{false};
  bool last_ok_{false};
  double t_{0.0};
  double fuel_{0.0};
};

// |q - q_final| over both MRP sets of the final attitude (the smaller distance).
double attitude_error(const Eigen::Vector3d& q, const Eigen::Vector3d& q_final);

}  // namespace rocksteady::merit
