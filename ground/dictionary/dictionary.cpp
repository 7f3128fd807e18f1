#include "ground/dictionary/dictionary.hpp"

#include <cmath>
#include <cstdio>

namespace rocksteady::ground::dictionary {

const std::vector<Channel>& channels() {
  return generated::channels();
}

const Channel* find_channel(const std::string& channel) {
  for (const Channel& c : channels()) {
    if (channel == c.channel) return &c;
  }
  return nullptr;
}

int find_point(const Channel& c, const std::string& key) {
  for (int i = 0; i < c.point_count; ++i) {
    if (key == c.points[i].key) return i;
  }
  return -1;
}

int limit_level(const Point& p, double v) {
  if (std::isnan(v)) return 2;
  if (v < p.red_lo || v > p.red_hi) return 2;
  if (v < p.yellow_lo || v > p.yellow_hi) return 1;
  return 0;
}

std::optional<std::string> enum_name(const std::string& enum_name, int value) {
  const auto& e = generated::enums();
  const auto it = e.find(enum_name);
  if (it == e.end()) return std::nullopt;
  const auto v = it->second.find(value);
  if (v == it->second.end()) return std::nullopt;
  return v->second;
}

std::optional<int> enum_value(const std::string& enum_name, const std::string& name) {
  const auto& e = generated::enums();
  const auto it = e.find(enum_name);
  if (it == e.end()) return std::nullopt;
  for (const auto& [value, n] : it->second) {
    if (n == name) return value;
  }
  return std::nullopt;
}

std::vector<std::string> enum_names(const std::string& enum_name) {
  std::vector<std::string> names;
  const auto& e = generated::enums();
  const auto it = e.find(enum_name);
  if (it == e.end()) return names;
  for (const auto& [value, n] : it->second) names.push_back(n);
  return names;
}

std::string format_value(const Point& p, double v) {
  if (p.enum_name[0] != '\0' && std::isfinite(v) && std::trunc(v) == v) {
    if (auto n = enum_name(p.enum_name, static_cast<int>(v))) return *n;
  }
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

const std::vector<EventInfo>& events() {
  return generated::events();
}

const EventInfo* find_event(int id) {
  for (const EventInfo& e : events()) {
    if (e.id == id) return &e;
  }
  return nullptr;
}

const std::string& json_text() {
  return generated::json_text();
}

}  // namespace rocksteady::ground::dictionary
