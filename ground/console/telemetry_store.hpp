// What the ground server has heard on the bus: for every channel of the dictionary the latest
// sample and a bounded history (at most one sample per `min_interval_ms` of wall time, the newest
// winning, so a lockstep run at thousands of ticks per second keeps a readable history), and the
// events and acknowledgements with their names. Thread-safe: the bus thread adds, HTTP threads
// read. Timestamps are wall-clock milliseconds since the epoch (reception time: Open MCT's UTC time
// system); the on-board time is a point like any other ("t").
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "ground/dictionary/dictionary.hpp"

namespace rocksteady::ground::console {

struct Sample {
  double utc_ms{0.0};
  std::vector<double> values;  // the channel's points, in dictionary order
  std::string text;            // the message's text field, if it has one
};

struct EventRecord {
  std::uint64_t index{0};  // position in the server's event stream, from 1
  double utc_ms{0.0};
  double t{0.0};  // on-board time
  int severity{0};
  std::string severity_name;
  int id{0};
  std::string name;  // the dictionary's event name
  int arg0{0}, arg1{0};
  std::string text;
};

struct ChannelStats {
  std::uint64_t received{0};
  std::uint64_t rejected{0};  // failed the safe decode
  double last_utc_ms{-1.0};   // < 0: never heard
};

class TelemetryStore {
 public:
  struct Options {
    double min_interval_ms{50.0};
    std::size_t history{20000};  // samples kept per channel
    std::size_t events{5000};
  };
  TelemetryStore();
  explicit TelemetryStore(const Options& options);

  // A raw message from the bus. Returns false (and counts it) if it does not decode safely or the
  // channel is not in the dictionary.
  bool add(const std::string& channel, const void* data, int len, double utc_ms);

  // Samples of one point within [start, end] (ms), oldest first: pairs (utc, value).
  std::vector<std::pair<double, double>> history(const std::string& channel, int point,
                                                 double start_ms, double end_ms) const;
  // The latest sample of a channel (empty values if none yet).
  Sample latest(const std::string& channel) const;
  // Samples newer than `after_ms`, at most one per channel (the newest): the real-time feed.
  std::map<std::string, Sample> newer_than(double after_ms) const;
  // Events with index > after_index, oldest first.
  std::vector<EventRecord> events_after(std::uint64_t after_index) const;
  std::map<std::string, ChannelStats> stats() const;

 private:
  struct ChannelData {
    const dictionary::Channel* dict{nullptr};
    std::deque<Sample> history;
    Sample latest;
    ChannelStats stats;
    double bucket_start_ms{0.0};  // reception time of the newest history sample's first message
  };
  Options options_;
  mutable std::mutex mutex_;
  std::map<std::string, ChannelData> channels_;
  std::deque<EventRecord> events_;
  std::uint64_t event_count_{0};
};

}  // namespace rocksteady::ground::console
