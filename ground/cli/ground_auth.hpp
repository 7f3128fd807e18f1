// The ground side of command security (fsw/auth/auth.hpp): every command and uplink chunk leaves
// with the key's next message counter and its HMAC, and every acknowledgement is checked for the
// flight's downlink authenticator, so a forged acknowledgement is reported as forged.
//
// One configuration per process, set once by main (or a test) before anything is sent:
//   --key-file PATH (or $ROCKSTEADY_KEY_FILE): the command keys (mode 0600, owner only);
//   --key-id N (or $ROCKSTEADY_KEY_ID): which key signs (default: the lowest id in the file; after
//     a KEY_ROTATE, the new id);
//   --lab (or $ROCKSTEADY_LAB_MODE=1): a lab-mode flight: nothing is signed, acknowledgements are
//     shown as unauthenticated.
// Neither: sending fails with a usage error that says so.
//
// Counters: one per key, shared by every sender of this user: "<state dir>/ground-key-<id>-counter"
// under an exclusive lock, and never below the wall clock in microseconds, so consoles with
// separate state directories (and a reinstalled ground) still count upwards. Lab mode keeps the
// per-sender sequence files.
#pragma once

#include <cstdint>
#include <string>

#include "fsw/auth/auth.hpp"
#include "rocksteady/cmd_ack_t.hpp"
#include "rocksteady/event_t.hpp"
#include "rocksteady/ground_cmd_t.hpp"
#include "rocksteady/param_table_t.hpp"
#include "rocksteady/trajectory_chunk_t.hpp"

namespace rocksteady::ground::cli {

struct AuthOptions {
  std::string key_file;  // "" = $ROCKSTEADY_KEY_FILE
  std::int32_t key_id{0};  // 0 = $ROCKSTEADY_KEY_ID, else the lowest id in the file
  bool lab{false};         // also $ROCKSTEADY_LAB_MODE=1
};

// Loads the key file (permission-checked) or selects lab mode. Returns "" or the error.
std::string configure_auth(const AuthOptions& options);
// Forgets the configuration (tests).
void reset_auth();
bool auth_configured();
bool auth_lab_mode();
std::int32_t auth_key_id();  // 0 in lab mode

// The next message counter: the key's (keys) or the sender's sequence number (lab mode), from
// `state_dir`. Throws std::runtime_error when not configured or the state file is unusable.
// `at_least`: the counter returned is not below it (a counter given by the operator, --seq, moves
// the key's counter file forward with it).
std::int64_t next_counter(const std::string& state_dir, std::int32_t sender_id,
                          std::int64_t at_least = 1);

// Stamps key_id and mac (the counter must already be in seq). No-op in lab mode (key 0, zero MAC).
// Throws std::runtime_error when not configured.
void authenticate(rocksteady::ground_cmd_t& cmd);
void authenticate(rocksteady::trajectory_chunk_t& chunk);

enum class AckAuth { kAuthentic, kForged, kLabMode };
// Checks an acknowledgement's downlink authenticator (kLabMode when the ground is in lab mode).
AckAuth verify_ack(const rocksteady::cmd_ack_t& ack);
// The same for an event (the flight signs its events, the watchdog thread's included; the
// plant's events come from the simulator, not the spacecraft, and carry none).
AckAuth verify_event(const rocksteady::event_t& event);
// The same for the parameter read-back (RS_PARAMS).
AckAuth verify_params(const rocksteady::param_table_t& table);

}  // namespace rocksteady::ground::cli
