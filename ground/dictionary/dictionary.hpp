// The ground's telemetry and command dictionary (ground/dictionary/README.md). Generated at build
// time by rocksteady-dictgen from dictionary.yaml, lcmtypes/*.lcm and the flight's own name tables;
// this header is its C++ face. One dictionary names events and enums in rocksteady-ground monitor,
// log2csv and the browser console, and gives every telemetry point its units and yellow/red limits.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "wire/codec.hpp"

namespace rocksteady::ground::dictionary {

// One numeric element of a channel: a scalar field or one element of an array field (key
// "omega_hat_0", "omega_d_3_1": the CSV column names of log2csv). Limits are +-inf where none.
struct Point {
  const char* key;
  const char* field;
  const char* units;
  const char* enum_name;  // "" when the value is a plain number
  double yellow_lo, yellow_hi;
  double red_lo, red_hi;
};

// Decodes one message of the channel's type safely (wire::decode) and writes its points in
// order into `out` (capacity: the channel's point count) and its text field, if any, into `text`.
using DecodeFn = bool (*)(const void* data, int len, double* out, std::string& text,
                          wire::DecodeStatus& status);

struct Channel {
  const char* channel;  // "RS_GNC_TLM"
  const char* type;     // "gnc_telemetry_t"
  const char* title;
  const Point* points;
  int point_count;
  DecodeFn decode;
  bool has_text;
};

struct EventInfo {
  int id;
  const char* name;      // the flight's name (fsw::to_string)
  const char* severity;  // the severity the flight raises it with
};

// Every channel of the bus, in lcmtypes/ order.
const std::vector<Channel>& channels();
const Channel* find_channel(const std::string& channel);
// Index of a point of a channel by key, or -1.
int find_point(const Channel& c, const std::string& key);

// Limit state of a value: 0 nominal, 1 yellow, 2 red.
int limit_level(const Point& p, double v);

// Enums by name: mode, law, phase, reference, severity, boolean (the dictionary's) and opcode,
// reason, event (the flight's). The name of a value, or nullopt when it has none.
std::optional<std::string> enum_name(const std::string& enum_name, int value);
// The value of a name (exact match), or nullopt.
std::optional<int> enum_value(const std::string& enum_name, const std::string& name);
// The names of an enum in value order.
std::vector<std::string> enum_names(const std::string& enum_name);
// A point's value as text: its enum name when it has one ("HOLD"), else the number.
std::string format_value(const Point& p, double v);

// The flight's events with their severities.
const std::vector<EventInfo>& events();
const EventInfo* find_event(int id);

// The whole dictionary as JSON (what the server sends the browser).
const std::string& json_text();

namespace generated {
const std::vector<Channel>& channels();
const std::map<std::string, std::map<int, std::string>>& enums();
const std::vector<EventInfo>& events();
const std::string& json_text();
}  // namespace generated

}  // namespace rocksteady::ground::dictionary
