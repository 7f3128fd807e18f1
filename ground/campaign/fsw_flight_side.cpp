#include "ground/campaign/fsw_flight_side.hpp"

#include <algorithm>
#include <stdexcept>

#include "fsw/executive/executive.hpp"

namespace rocksteady::campaign {

namespace {
constexpr std::int32_t kCampaignSource = 7;  // the campaign's "ground station" id
constexpr std::int32_t kUploadId = 1;
}  // namespace

FswFlightSide::FswFlightSide() : app_(std::make_unique<fsw::FlightApp>()) {}

void FswFlightSide::setup(const FlightSetup& s) {
  fsw::FlightConfig cfg;
  cfg.gnc = s.params;
  cfg.executive = fsw::lockstep_executive(s.params.dt);
  const fsw::InitResult r = app_->init(cfg, clock_);
  if (!r.ok) {
    throw std::runtime_error(std::string("flight software rejected parameter ") + r.field + ": " +
                             r.reason);
  }
  if (gyro_.configure(hal::SensorConfig{}) != hal::SensorConfigError::kOk ||
      star_.configure(hal::SensorConfig{}) != hal::SensorConfigError::kOk) {
    throw std::runtime_error("HAL sensor configuration rejected");
  }
  const hal::BankConfigCheck bc =
      bank_.configure(hal::default_thruster_bank_config(s.params.rcs.u_max), &s.params.rcs);
  if (!bc.ok()) {
    throw std::runtime_error(std::string("HAL thruster bank rejected its wiring: ") +
                             hal::to_string(bc.error));
  }
  start_mode_ = s.start_mode;
  trajectory_ = s.trajectory;
  seq_ = 0;
  ticks_ = 0;
  started_ = false;
  if (trajectory_ != nullptr) {
    // The chunked uplink, exactly as the ground sends it.
    const gnc::TrajectoryTable& t = *trajectory_;
    const int chunks = (t.count + fsw::kChunkSamples - 1) / fsw::kChunkSamples;
    for (int c = 0; c < chunks; ++c) {
      fsw::TrajectoryChunk ch;
      ch.upload_id = kUploadId;
      ch.chunk_index = c;
      ch.chunk_count = chunks;
      ch.total_samples = t.count;
      ch.crc32 = t.checksum;
      ch.n = std::min(fsw::kChunkSamples, t.count - c * fsw::kChunkSamples);
      for (int i = 0; i < ch.n; ++i) ch.samples[i] = t.samples[c * fsw::kChunkSamples + i];
      const fsw::ChunkStatus st = app_->receive_chunk(ch);
      if (st != fsw::ChunkStatus::kStored) {
        throw std::runtime_error(std::string("flight software refused uplink chunk: ") +
                                 fsw::to_string(st));
      }
    }
  }
}

void FswFlightSide::command(fsw::Opcode op, std::initializer_list<double> args) {
  fsw::GroundCommand c;
  c.seq = ++seq_;
  c.source = kCampaignSource;
  c.opcode = static_cast<std::int32_t>(op);
  c.arg_count = static_cast<std::int32_t>(args.size());
  std::copy(args.begin(), args.end(), c.args.begin());
  const fsw::CommandAck ack = app_->submit(c);
  if (!ack.accepted) {
    throw std::runtime_error(std::string("flight software rejected ") + fsw::to_string(op) +
                             ": " + ack.text);
  }
}

void FswFlightSide::step(const gnc::SensorSample& sample, gnc::GncOutput& out) {
  // Plant -> HAL -> flight application (identity alignment: the plant reports in the body frame).
  const hal::BodyRate rate = gyro_.read({sample.t, sample.gyro_rate, sample.gyro_valid}, sample.t);
  const hal::BodyAttitude att = star_.read({sample.t, sample.star_quat, sample.star_valid}, sample.t);
  app_->gnc_tick(hal::make_sample(sample.t, rate, att), outputs_);
  fsw::Event e;
  while (app_->pop_event(e)) {
  }
  out = app_->core_output();
  // Flight application -> thruster bank -> the forces the plant applies.
  hal::ThrusterOutputs thrusters;
  bank_.command(outputs_.command, thrusters);
  out.command.force = bank_.channel_forces(thrusters);
  out.command.enabled = thrusters.enabled;

  // After the first tick (the estimator has a state), the ground's commands for this run; they take
  // effect at the next tick boundary.
  ++ticks_;
  if (!started_ && ticks_ == 1) {
    if (trajectory_ != nullptr) command(fsw::Opcode::kLoadTrajectory, {double(kUploadId)});
    command(fsw::Opcode::kSetMode, {double(static_cast<int>(start_mode_))});
  }
  if (!started_ && ticks_ > 1) {
    if (app_->mode() != start_mode_) {
      throw std::runtime_error(std::string("flight software did not enter ") +
                               gnc::to_string(start_mode_) + " (still " +
                               gnc::to_string(app_->mode()) + ")");
    }
    started_ = true;
  }
}

}  // namespace rocksteady::campaign
