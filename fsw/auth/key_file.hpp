// Command keys and the persisted replay state on disk (start-up and the bus loop only: never inside
// a tick). Shared by rocksteady-fsw and the ground tools.
//
// Key file: text, one key per line, "<id> <64 hex digits>" (id a positive integer), '#' comments.
// It must be a regular file owned by the user running the program with no group/other permission
// bits (0600 or 0400); it is opened without following symlinks and checked on the open descriptor.
// Errors name the file, the line and the reason, never a key's digits. Key material is wiped from
// the stack buffers after parsing.
//
// State file (fsw only): "rocksteady-auth-state 1", "active <id>", then "counter <id> <highest>"
// lines. Written atomically (temporary file, fsync, rename) whenever the security state changes, so
// after a restart every counter the flight has accepted is refused (fsw/auth/auth.hpp).
#pragma once

#include <string>

#include "fsw/auth/auth.hpp"

namespace rocksteady::fsw::auth {

// Loads the key file into `out`. Returns "" or the error ("<path>: line 3: ...").
std::string load_key_file(const std::string& path, KeySet& out);
// Writes a new key file (mode 0600, fails if it exists) with `count` fresh random keys, ids first_id..
std::string generate_key_file(const std::string& path, int count, std::int32_t first_id = 1);

// Reads the state file into config (active key, restored counters). A missing file is a first
// start: returns "" and sets `missing`.
std::string load_state_file(const std::string& path, SecurityConfig& config, bool& missing);
// Writes the state atomically. Returns "" or the error.
std::string write_state_file(const std::string& path, const SecurityState& state);

}  // namespace rocksteady::fsw::auth
