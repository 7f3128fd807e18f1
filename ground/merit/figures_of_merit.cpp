#include "ground/merit/figures_of_merit.hpp"

#include <algorithm>

namespace rocksteady::merit {

void ConvergenceTracker::add(double t, double value, double fuel_kg) {
  const bool ok = value <= tol_;
  if (ok && (!have_ || !last_ok_)) {  // start of a (possibly final) satisfied stretch
    t_ = t;
    fuel_ = fuel_kg;
  }
  last_ok_ = ok;
  have_ = true;
}

std::optional<double> ConvergenceTracker::time() const {
  if (!converged()) return std::nullopt;
  return t_;
}

std::optional<double> ConvergenceTracker::fuel_kg() const {
  if (!converged()) return std::nullopt;
  return fuel_;
}

double attitude_error(const Eigen::Vector3d& q, const Eigen::Vector3d& q_final) {
  const double n = q_final.squaredNorm();
  if (n == 0.0) return q.norm();
  const Eigen::Vector3d shadow = -q_final / n;  // the same attitude, other MRP set
  return std::min((q - q_final).norm(), (q - shadow).norm());
}

}  // namespace rocksteady::merit
