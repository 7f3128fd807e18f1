// Bus messages as CSV rows, and log2csv: an LCM log (lcm-logger's format, read with lcm::LogFile)
// converted one channel at a time. Every event is decoded with wire::safe_decode; whatever
// fails (truncated, wrong type, out-of-range fields) is counted and left out, never guessed at.
// Columns: log_utime (the log's receive time, microseconds since the epoch), then every field of
// the message in the order of its .lcm file; arrays are expanded as name_0, name_1, ... (two
// dimensions: name_i_j), then, for every field the dictionary (ground/dictionary) gives an enum, a
// column "<column>_name" with the value's name (mode_name HOLD, id_name sensor_timeout, ...).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "wire/codec.hpp"

namespace rocksteady::ground::cli {

// The channels log2csv understands (each one type, lcmtypes/channels.hpp).
std::vector<std::string> csv_channels();
bool csv_supported(const std::string& channel);

// The header of a channel's CSV (column names, without the line break); empty if unsupported.
std::vector<std::string> csv_header(const std::string& channel);

// One message's row, or false (and the reason in `status`) if it does not decode safely.
bool csv_row(const std::string& channel, const void* data, int len, std::int64_t log_utime,
             std::vector<std::string>& row, wire::DecodeStatus& status);

// CSV text of one row (quoted where needed), with the line break.
std::string csv_line(const std::vector<std::string>& cells);

struct Log2CsvStats {
  std::uint64_t events{0};      // events in the log
  std::uint64_t on_channel{0};  // events of the chosen channel
  std::uint64_t written{0};     // rows written
  wire::RxCounters rx{};   // decode outcomes of the channel's events
  std::uint64_t rejected() const { return on_channel - written; }
};

// Converts `channel` of the log at `log_path` into CSV on `out` (header first, even with no rows).
// Throws std::runtime_error when the log cannot be opened or the channel is not supported.
Log2CsvStats log2csv(const std::string& log_path, const std::string& channel, std::ostream& out);

// "3 rejected: 2 too short, 1 bad fingerprint" (only the non-zero causes).
std::string describe_rejections(const wire::RxCounters& rx);

}  // namespace rocksteady::ground::cli
