// Processor-in-the-loop test harness: real rocksteady-plant / rocksteady-fsw processes on an LCM bus
// inside a private network namespace (main() re-executes the test binary under `unshare -rn` with
// the loopback up and the LCM multicast group routed to it), and a test-side bus endpoint that
// sends commands or raw bytes and collects telemetry, acknowledgements, events and thruster commands.
#pragma once

#include <lcm/lcm.h>
#include <sys/types.h>

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "rocksteady/cmd_ack_t.hpp"
#include "rocksteady/event_t.hpp"
#include "rocksteady/gnc_telemetry_t.hpp"
#include "rocksteady/plant_truth_t.hpp"
#include "rocksteady/thruster_cmd_t.hpp"

namespace rocksteady::pil {

// Paths of the built programs and the configuration folder (from CMake).
std::string fsw_exe();
std::string plant_exe();
std::string planner_exe();  // rocksteady-planner (when built)
std::string config_dir();
// A fresh scratch folder for one test.
std::string scratch_dir(const std::string& name);
// Writes `text` to `path`; a copy of a file with whole lines replaced (line starting with key).
void write_file(const std::string& path, const std::string& text);
std::string read_file(const std::string& path);
void copy_with_lines(const std::string& from, const std::string& to,
                     const std::map<std::string, std::string>& line_starting_with);

std::string lcm_url(int port);

// A child process; killed (SIGKILL) and reaped when destroyed.
class Process {
 public:
  Process(const std::vector<std::string>& argv, const std::string& log_path);
  ~Process();
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  pid_t pid() const { return pid_; }
  bool running();
  void signal(int sig);
  // Waits up to timeout_s for the exit; true and the exit code (or 128 + signal) when it exited.
  bool wait(double timeout_s, int* status = nullptr);
  const std::string& log_path() const { return log_; }

 private:
  pid_t pid_{-1};
  bool reaped_{false};
  int status_{0};
  std::string log_;
};

// The test's own bus endpoint.
class TestBus {
 public:
  explicit TestBus(const std::string& url);
  ~TestBus();
  TestBus(const TestBus&) = delete;
  TestBus& operator=(const TestBus&) = delete;

  // Serves the bus until pred() holds or timeout_s passes. Returns pred().
  bool spin_until(const std::function<bool()>& pred, double timeout_s);
  void spin_for(double seconds);

  void send_command(std::int64_t seq, std::int32_t opcode, const std::vector<double>& args,
                    std::int32_t sender = 1);
  void publish_raw(const char* channel, const std::vector<std::uint8_t>& bytes);

  bool have_tlm{false};
  rocksteady::gnc_telemetry_t tlm{};   // newest telemetry
  std::uint64_t tlm_count{0};
  std::vector<rocksteady::cmd_ack_t> acks;
  std::vector<rocksteady::event_t> events;
  bool have_thruster{false};
  rocksteady::thruster_cmd_t thruster{};  // newest thruster command
  std::uint64_t thruster_count{0};
  std::uint64_t thruster_firing_count{0};  // commands with at least one thruster on
  std::vector<rocksteady::plant_truth_t> truths;  // every RS_PLANT_TRUTH received, in order
  // Called with each telemetry message as it arrives (unset: only the newest is kept in tlm).
  std::function<void(const rocksteady::gnc_telemetry_t&)> on_each_tlm;

  bool has_event(std::int32_t id) const;
  const rocksteady::cmd_ack_t* ack_for(std::int64_t seq, std::int32_t sender = 1) const;

 private:
  static void on_tlm(const lcm_recv_buf_t* rbuf, const char* ch, void* self);
  static void on_ack(const lcm_recv_buf_t* rbuf, const char* ch, void* self);
  static void on_event(const lcm_recv_buf_t* rbuf, const char* ch, void* self);
  static void on_thruster(const lcm_recv_buf_t* rbuf, const char* ch, void* self);
  static void on_truth(const lcm_recv_buf_t* rbuf, const char* ch, void* self);
  lcm_t* lcm_{nullptr};
};

// "key=value" pairs of the plant's `summary:` line (empty map if there is none).
std::map<std::string, std::string> plant_summary(const std::string& log_text);

}  // namespace rocksteady::pil
