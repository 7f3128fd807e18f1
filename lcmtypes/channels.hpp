// The bus: one LCM channel per message type (DESIGN.md "The bus"). Every process names channels
// through these constants only.
#pragma once

namespace rocksteady::channels {

inline constexpr const char* kSensors = "RS_SENSORS";            // sensor_frame_t, plant -> fsw
inline constexpr const char* kThrusterCmd = "RS_THRUSTER_CMD";   // thruster_cmd_t, fsw -> plant
inline constexpr const char* kGncTelemetry = "RS_GNC_TLM";       // gnc_telemetry_t, fsw -> ground
inline constexpr const char* kEvents = "RS_EVENTS";              // event_t, fsw/plant -> ground
inline constexpr const char* kGroundCmd = "RS_GROUND_CMD";       // ground_cmd_t, ground -> fsw
inline constexpr const char* kCmdAck = "RS_CMD_ACK";             // cmd_ack_t, fsw -> ground
inline constexpr const char* kPlantTruth = "RS_PLANT_TRUTH";     // plant_truth_t, plant -> logs
inline constexpr const char* kTrajUplink = "RS_TRAJ_UPLINK";     // trajectory_chunk_t, ground -> fsw
inline constexpr const char* kParams = "RS_PARAMS";              // param_table_t, fsw -> ground
inline constexpr const char* kPlantFault = "RS_PLANT_FAULT";     // plant_fault_cmd_t, ground -> plant

}  // namespace rocksteady::channels
