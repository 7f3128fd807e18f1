#include "ground/campaign/fsw_flight_side.hpp"

#include <algorithm>
#include <stdexcept>

#include "fsw/bus/bus_mapping.hpp"
#include "fsw/executive/executive.hpp"
#include "wire/uplink.hpp"

namespace rocksteady::campaign {

namespace {
constexpr std::int32_t kCampaignSource = 7;  // the campaign's "ground station" id
constexpr std::int32_t kUploadId = 1;
}  // namespace

void FswFlightSide::setup(const FlightSetup& s, hal::SensorSource& sensors,
                          hal::ThrusterSink& thrusters) {
  computer_ = std::make_unique<fsw::FlightComputer>(sensors, thrusters);
  fsw::FlightConfig cfg;
  cfg.gnc = s.params;
  cfg.executive = fsw::lockstep_executive(s.params.dt);
  // In process, no bus: the campaign is the only commander of this computer. Lab mode (explicit,
  // flagged in its telemetry); the bus's authentication is tested in tests/fsw and tests/pil.
  cfg.security.lab_mode = true;
  const fsw::InitResult r = computer_->init(fsw::default_computer_config(cfg), clock_);
  if (!r.ok) {
    throw std::runtime_error(std::string("flight software rejected parameter ") + r.field + ": " +
                             r.reason);
  }
  start_mode_ = s.start_mode;
  have_trajectory_ = s.trajectory != nullptr;
  seq_ = 0;
  ticks_ = 0;
  switches_ = 0;
  refusals_ = 0;
  started_ = false;
  if (s.trajectory != nullptr) {
    // The chunked uplink, exactly as the ground sends it over the bus.
    const int chunks = wire::chunk_count(s.trajectory->count);
    rocksteady::trajectory_chunk_t msg;
    fsw::TrajectoryChunk chunk;
    for (int c = 0; c < chunks; ++c) {
      if (!wire::make_chunk(*s.trajectory, kUploadId, c, msg)) {
        throw std::runtime_error("trajectory table cannot be chunked");
      }
      fsw::bus::to_chunk(msg, chunk);
      const fsw::ChunkStatus st = computer_->receive_chunk(chunk);
      if (st != fsw::ChunkStatus::kStored) {
        throw std::runtime_error(std::string("flight software refused uplink chunk: ") +
                                 fsw::to_string(st));
      }
    }
  }
}

fsw::CommandAck FswFlightSide::try_command(fsw::Opcode op, std::initializer_list<double> args) {
  fsw::GroundCommand c;
  c.seq = ++seq_;
  c.source = kCampaignSource;
  c.opcode = static_cast<std::int32_t>(op);
  c.arg_count = static_cast<std::int32_t>(args.size());
  std::copy(args.begin(), args.end(), c.args.begin());
  return computer_->submit(c);
}

bool FswFlightSide::uplink_plan(const gnc::TrajectoryTable& table, std::int32_t upload_id,
                                bool enter_track, gnc::LawId law, std::string& why) {
  // The chunked uplink exactly as the ground sends it over the bus (wire::make_chunk, then the
  // flight side's bus mapping), then the commands.
  const int chunks = wire::chunk_count(table.count);
  rocksteady::trajectory_chunk_t msg;
  fsw::TrajectoryChunk chunk;
  for (int c = 0; c < chunks; ++c) {
    if (!wire::make_chunk(table, upload_id, c, msg)) {
      why = "trajectory table cannot be chunked";
      return false;
    }
    fsw::bus::to_chunk(msg, chunk);
    const fsw::ChunkStatus st = computer_->receive_chunk(chunk);
    if (st != fsw::ChunkStatus::kStored) {
      why = std::string("uplink chunk refused: ") + fsw::to_string(st);
      return false;
    }
  }
  fsw::CommandAck ack = try_command(fsw::Opcode::kLoadTrajectory, {double(upload_id)});
  if (!ack.accepted) {
    why = std::string("LOAD_TRAJECTORY refused: ") + ack.text;
    try_command(fsw::Opcode::kAbortUplink, {double(upload_id)});  // free the uplink
    return false;
  }
  if (enter_track) {
    ack = try_command(fsw::Opcode::kSetLaw, {double(static_cast<int>(law)), 2.0});
    if (!ack.accepted) {
      why = std::string("SET_LAW (fuel-optimal reference) refused: ") + ack.text;
      return false;
    }
  }
  return true;
}

void FswFlightSide::command(fsw::Opcode op, std::initializer_list<double> args) {
  fsw::GroundCommand c;
  c.seq = ++seq_;
  c.source = kCampaignSource;
  c.opcode = static_cast<std::int32_t>(op);
  c.arg_count = static_cast<std::int32_t>(args.size());
  std::copy(args.begin(), args.end(), c.args.begin());
  const fsw::CommandAck ack = computer_->submit(c);
  if (!ack.accepted) {
    throw std::runtime_error(std::string("flight software rejected ") + fsw::to_string(op) +
                             ": " + ack.text);
  }
}

void FswFlightSide::step() {
  computer_->step();  // sensors in, thrusters out: through the ports
  fsw::Event e;
  while (computer_->pop_event(e)) {
    if (e.id == fsw::EventId::kTrajectorySwitched) ++switches_;
    if (e.id == fsw::EventId::kTrajectoryStale) ++refusals_;
  }
  // After the first tick (the estimator has a state), the ground's commands for this run; they take
  // effect at the next tick boundary.
  ++ticks_;
  if (!started_ && ticks_ == 1) {
    if (have_trajectory_) command(fsw::Opcode::kLoadTrajectory, {double(kUploadId)});
    command(fsw::Opcode::kSetMode, {double(static_cast<int>(start_mode_))});
  }
  if (!started_ && ticks_ > 1) {
    if (computer_->mode() != start_mode_) {
      throw std::runtime_error(std::string("flight software did not enter ") +
                               gnc::to_string(start_mode_) + " (still " +
                               gnc::to_string(computer_->mode()) + ")");
    }
    started_ = true;
  }
}

}  // namespace rocksteady::campaign
