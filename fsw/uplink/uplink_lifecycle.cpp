#include "fsw/uplink/uplink_lifecycle.hpp"

#include <cinttypes>

#include <Eigen/Eigenvalues>

#include "gnc/model/mass_properties.hpp"
#include "gnc/model/rcs.hpp"

namespace rocksteady::fsw {

void UplinkLifecycle::reset() {
  uplink_.clear();
  chunks_rejected_ = 0;
  loaded_ = 0;
}

ChunkStatus UplinkLifecycle::receive(const TrajectoryChunk& chunk, EventLog& log) {
  const ChunkResult r = uplink_.receive(chunk);
  if (r.status == ChunkStatus::kOtherUplinkActive) {
    ++chunks_rejected_;
    log.emit(Severity::kWarning, EventId::kChunkRejected, chunk.upload_id,
             static_cast<std::int32_t>(r.status),
             "uplink %" PRId32 " chunk %" PRId32 " refused: uplink %" PRId32
             " in progress (%" PRId32 "/%" PRId32 "); ABORT_UPLINK %" PRId32 " ends it",
             chunk.upload_id, chunk.chunk_index, r.active_id, uplink_.chunks_received(),
             uplink_.chunk_count(), r.active_id);
    return r.status;
  }
  if (r.status != ChunkStatus::kStored) {
    ++chunks_rejected_;
    log.emit(Severity::kWarning, EventId::kChunkRejected, chunk.upload_id,
             static_cast<std::int32_t>(r.status),
             "uplink %" PRId32 " chunk %" PRId32 " rejected: %s", chunk.upload_id,
             chunk.chunk_index, to_string(r.status));
    return r.status;
  }
  if (r.started) {
    log.emit(Severity::kInfo, EventId::kUplinkStarted, chunk.upload_id, chunk.chunk_count,
             "trajectory uplink %" PRId32 " started: %" PRId32 " samples in %" PRId32 " chunks",
             chunk.upload_id, chunk.total_samples, chunk.chunk_count);
  }
  if (r.completed) {
    log.emit(Severity::kInfo, EventId::kUplinkComplete, chunk.upload_id, chunk.chunk_count,
             "trajectory uplink %" PRId32 " complete: ready to load", chunk.upload_id);
  }
  return r.status;
}

namespace {

// Beyond gnc::validate_trajectory (samples only): what the flight will actually follow.
//  - |omega_d_dot| at every sample at most the largest angular acceleration the thrusters can give
//    the body: sum of the torque columns' norms times u_max over lambda_min(J_hat) (Eqs. 1, 5); a
//    plan asking for more cannot be tracked (the finding: +-1 rad/s^2 drove |omega_r| to 9.9 rad/s);
//  - |omega_d| of the cubic Hermite interpolation the reference uses (gnc::interpolate) between
//    samples, at kProbes points per interval, within eps_trans (1% for a plan that rides the bound).
constexpr int kProbes = 16;
constexpr double kInterpolationSlack = 1.01;

const char* dynamics_error(const gnc::TrajectoryTable& t, const gnc::GncParams& p) {
  const gnc::Mat3 j = gnc::total_inertia(p.mass_hat);
  const Eigen::SelfAdjointEigenSolver<gnc::Mat3> es(j, Eigen::EigenvaluesOnly);
  const double j_min = es.eigenvalues()(0);
  const auto b = gnc::torque_matrix(p.rcs, p.mass_hat.r_so_bcm);
  double tau_max = 0.0;
  for (int i = 0; i < b.cols(); ++i) tau_max += b.col(i).norm() * p.rcs.u_max;
  const double alpha_max = j_min > 0.0 ? tau_max / j_min : 0.0;
  const double eps = p.guidance.eps_trans * kInterpolationSlack;
  for (int i = 0; i < t.count; ++i) {
    if (t.samples[static_cast<std::size_t>(i)].omega_d_dot.norm() > alpha_max) {
      return "omega_d_dot above what the thrusters can produce";
    }
  }
  for (int i = 0; i + 1 < t.count; ++i) {
    const double t0 = t.samples[static_cast<std::size_t>(i)].t;
    const double t1 = t.samples[static_cast<std::size_t>(i + 1)].t;
    for (int k = 1; k < kProbes; ++k) {
      const double tk = t0 + (t1 - t0) * static_cast<double>(k) / kProbes;
      if (gnc::interpolate(t, tk).omega_d.norm() > eps) {
        return "interpolated omega_d exceeds eps_trans between samples";
      }
    }
  }
  return nullptr;
}

}  // namespace

CommandCheck UplinkLifecycle::request_load(std::int32_t id, const gnc::GncParams& params,
                                           EventLog& log) {
  const double eps_trans = params.guidance.eps_trans;
  if (!uplink_.active() || uplink_.upload_id() != id) {
    return CommandCheck{RejectReason::kOutOfRange, 0, "no uplink with that id"};
  }
  if (uplink_.pending()) {
    return CommandCheck{RejectReason::kBusy, 0, "this table already waits for the tick boundary"};
  }
  if (!uplink_.complete()) {
    return CommandCheck{RejectReason::kUploadIncomplete, uplink_.chunks_received(),
                        "chunks missing: resend them, then load"};
  }
  const gnc::TrajectoryError e = uplink_.finalize(eps_trans);
  if (e != gnc::TrajectoryError::kOk) {
    log.emit(Severity::kWarning, EventId::kTrajectoryRejected, id, static_cast<std::int32_t>(e),
             "trajectory uplink %" PRId32 " rejected: %s; uplink discarded", id, gnc::to_string(e));
    uplink_.clear();
    return CommandCheck{RejectReason::kTrajectoryRejected, static_cast<std::int32_t>(e),
                        gnc::to_string(e)};
  }
  if (const char* why = dynamics_error(uplink_.table(), params); why != nullptr) {
    log.emit(Severity::kWarning, EventId::kTrajectoryRejected, id,
             static_cast<std::int32_t>(gnc::TrajectoryError::kRateAboveBound),
             "trajectory uplink %" PRId32 " rejected: %s; uplink discarded", id, why);
    uplink_.clear();
    return CommandCheck{RejectReason::kTrajectoryRejected,
                        static_cast<std::int32_t>(gnc::TrajectoryError::kRateAboveBound), why};
  }
  uplink_.set_pending(true);
  return CommandCheck{};
}

CommandCheck UplinkLifecycle::abort(std::int32_t id, EventLog& log) {
  if (!uplink_.active() || uplink_.upload_id() != id) {
    return CommandCheck{RejectReason::kOutOfRange, 0, "no uplink with that id"};
  }
  log.emit(Severity::kInfo, EventId::kUplinkAbandoned, id, uplink_.chunks_received(),
           "trajectory uplink %" PRId32 " aborted by ground (%" PRId32 " of %" PRId32 " chunks)",
           id, uplink_.chunks_received(), uplink_.chunk_count());
  uplink_.clear();  // a queued hand-over of this uplink finds nothing pending and is skipped
  return CommandCheck{};
}

bool UplinkLifecycle::hand_over(std::int32_t id, gnc::Gnc& core, EventLog& log) {
  if (!pending(id)) return false;  // aborted meanwhile
  const gnc::TrajectoryError e = core.load_trajectory(uplink_.table());
  if (e == gnc::TrajectoryError::kOk) {
    ++loaded_;
    // In TRACK the table is staged: the core switches to it (trajectory_switched) or refuses it as
    // stale (trajectory_stale) in this tick, after this event.
    log.emit(Severity::kInfo, EventId::kTrajectoryLoaded, id, uplink_.table().count,
             core.trajectories().switch_pending()
                 ? "trajectory uplink %" PRId32 " staged: %d samples, switch at this boundary"
                 : "trajectory uplink %" PRId32 " loaded: %d samples",
             id, uplink_.table().count);
  } else {
    log.emit(Severity::kError, EventId::kTrajectoryRejected, id, static_cast<std::int32_t>(e),
             "trajectory uplink %" PRId32 " refused by the core: %s", id, gnc::to_string(e));
  }
  uplink_.clear();
  return e == gnc::TrajectoryError::kOk;
}

}  // namespace rocksteady::fsw
