#include "ground/console/telemetry_store.hpp"

#include <algorithm>

namespace rocksteady::ground::console {

TelemetryStore::TelemetryStore() : TelemetryStore(Options{}) {}

TelemetryStore::TelemetryStore(const Options& options) : options_(options) {
  for (const dictionary::Channel& c : dictionary::channels()) channels_[c.channel].dict = &c;
}

bool TelemetryStore::add(const std::string& channel, const void* data, int len, double utc_ms) {
  const auto it = channels_.find(channel);  // the map's keys never change after construction
  if (it == channels_.end()) return false;
  const dictionary::Channel& dict = *it->second.dict;
  Sample s;
  s.utc_ms = utc_ms;
  s.values.resize(static_cast<std::size_t>(dict.point_count));
  wire::DecodeStatus status{};
  const bool ok = dict.decode(data, len, s.values.data(), s.text, status);

  std::lock_guard<std::mutex> lock(mutex_);
  ChannelData& c = it->second;
  if (!ok) {
    ++c.stats.rejected;
    return false;
  }
  ++c.stats.received;
  c.stats.last_utc_ms = utc_ms;
  if (!c.history.empty() && utc_ms - c.bucket_start_ms < options_.min_interval_ms) {
    c.history.back() = s;  // the newest wins within the interval
  } else {
    c.bucket_start_ms = utc_ms;
    c.history.push_back(s);
    while (c.history.size() > options_.history) c.history.pop_front();
  }
  if (channel == channels::kEvents) {
    const auto value = [&](const char* key) {
      return static_cast<int>(
          s.values[static_cast<std::size_t>(dictionary::find_point(dict, key))]);
    };
    EventRecord e;
    e.index = ++event_count_;
    e.utc_ms = utc_ms;
    e.t = s.values[static_cast<std::size_t>(dictionary::find_point(dict, "t"))];
    e.severity = value("severity");
    e.severity_name = dictionary::enum_name("severity", e.severity).value_or("?");
    e.id = value("id");
    e.name = dictionary::enum_name("event", e.id).value_or("event " + std::to_string(e.id));
    e.arg0 = value("arg0");
    e.arg1 = value("arg1");
    e.text = s.text;
    events_.push_back(std::move(e));
    while (events_.size() > options_.events) events_.pop_front();
  }
  c.latest = std::move(s);
  return true;
}

std::vector<std::pair<double, double>> TelemetryStore::history(const std::string& channel,
                                                               int point, double start_ms,
                                                               double end_ms) const {
  std::vector<std::pair<double, double>> out;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = channels_.find(channel);
  if (it == channels_.end() || point < 0 || point >= it->second.dict->point_count) return out;
  for (const Sample& s : it->second.history) {
    if (s.utc_ms < start_ms || s.utc_ms > end_ms) continue;
    out.emplace_back(s.utc_ms, s.values[static_cast<std::size_t>(point)]);
  }
  return out;
}

Sample TelemetryStore::latest(const std::string& channel) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = channels_.find(channel);
  return it == channels_.end() ? Sample{} : it->second.latest;
}

std::map<std::string, Sample> TelemetryStore::newer_than(double after_ms) const {
  std::map<std::string, Sample> out;
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [name, c] : channels_) {
    if (!c.latest.values.empty() && c.latest.utc_ms > after_ms) out[name] = c.latest;
  }
  return out;
}

std::vector<EventRecord> TelemetryStore::events_after(std::uint64_t after_index) const {
  std::vector<EventRecord> out;
  std::lock_guard<std::mutex> lock(mutex_);
  for (const EventRecord& e : events_) {
    if (e.index > after_index) out.push_back(e);
  }
  return out;
}

std::map<std::string, ChannelStats> TelemetryStore::stats() const {
  std::map<std::string, ChannelStats> out;
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [name, c] : channels_) out[name] = c.stats;
  return out;
}

}  // namespace rocksteady::ground::console
