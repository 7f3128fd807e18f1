// Per-sender command sequence numbers that survive the process: the flight side accepts a command
// only if its seq is above the last one it accepted from that sender (fsw/README.md "Commands"), so
// every send takes the next number from a small state file, under an exclusive lock (two consoles
// of the same sender never get the same number). The number is written before the command is sent.
#pragma once

#include <cstdint>
#include <string>
#include <utility>

namespace rocksteady::ground::cli {

// $XDG_STATE_HOME/rocksteady, else $HOME/.local/state/rocksteady (empty if neither is set).
std::string default_state_dir();

// The state file of one sender in `dir`: "<dir>/ground-seq-<sender>".
std::string sequence_file(const std::string& dir, std::int32_t sender_id);

class SequenceStore {
 public:
  explicit SequenceStore(std::string path) : path_(std::move(path)) {}

  // Reserves the next number: max(last + 1, at_least), creating the directory and file as needed,
  // and persists it. Throws std::runtime_error (with the path) when the file cannot be used.
  std::int64_t next(std::int64_t at_least = 1);
  // The last reserved number (0 if none), without reserving.
  std::int64_t last() const;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace rocksteady::ground::cli
