#include "tests/pil/pil_harness.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "wire/codec.hpp"
#include "lcmtypes/channels.hpp"
#include "rocksteady/ground_cmd_t.hpp"

namespace rocksteady::pil {

std::string fsw_exe() { return ROCKSTEADY_FSW_EXE; }
std::string plant_exe() { return ROCKSTEADY_PLANT_EXE; }
#ifdef ROCKSTEADY_PLANNER_EXE
std::string planner_exe() { return ROCKSTEADY_PLANNER_EXE; }
#else
std::string planner_exe() { return "rocksteady-planner"; }
#endif
std::string config_dir() { return ROCKSTEADY_CONFIG_DIR; }

std::string scratch_dir(const std::string& name) {
  const std::string d = std::string(ROCKSTEADY_PIL_SCRATCH) + "/" + name;
  const std::string cmd = "rm -rf '" + d + "' && mkdir -p '" + d + "'";
  if (std::system(cmd.c_str()) != 0) throw std::runtime_error("cannot create " + d);
  return d;
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  f << text;
  if (!f) throw std::runtime_error("cannot write " + path);
}

std::string read_file(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

void copy_with_lines(const std::string& from, const std::string& to,
                     const std::map<std::string, std::string>& repl) {
  std::istringstream in(read_file(from));
  std::ostringstream out;
  std::string line;
  std::map<std::string, bool> used;
  while (std::getline(in, line)) {
    for (const auto& [key, value] : repl) {
      if (line.rfind(key, 0) == 0) {
        line = value;
        used[key] = true;
      }
    }
    out << line << '\n';
  }
  for (const auto& [key, value] : repl) {
    if (!used[key]) throw std::runtime_error(from + ": no line starting with '" + key + "'");
  }
  write_file(to, out.str());
}

std::string lcm_url(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
}

// ---------------------------------------------------------------------------------------------

Process::Process(const std::vector<std::string>& argv, const std::string& log_path)
    : log_(log_path) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    const int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
      close(fd);
    }
    execv(args[0], args.data());
    std::perror("execv");
    _exit(127);
  }
}

Process::~Process() {
  if (!reaped_ && pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

bool Process::running() {
  if (reaped_) return false;
  int st = 0;
  const pid_t r = waitpid(pid_, &st, WNOHANG);
  if (r == pid_) {
    reaped_ = true;
    status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    return false;
  }
  return true;
}

void Process::signal(int sig) {
  if (!reaped_) kill(pid_, sig);
}

bool Process::wait(double timeout_s, int* status) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (running()) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (status != nullptr) *status = status_;
  return true;
}

// ---------------------------------------------------------------------------------------------

TestBus::TestBus(const std::string& url) {
  lcm_ = lcm_create(url.c_str());
  if (lcm_ == nullptr) throw std::runtime_error("lcm_create failed for " + url);
  lcm_subscription_set_queue_capacity(
      lcm_subscribe(lcm_, channels::kGncTelemetry, &TestBus::on_tlm, this), 1000);
  lcm_subscribe(lcm_, channels::kCmdAck, &TestBus::on_ack, this);
  lcm_subscription_set_queue_capacity(
      lcm_subscribe(lcm_, channels::kEvents, &TestBus::on_event, this), 1000);
  lcm_subscribe(lcm_, channels::kThrusterCmd, &TestBus::on_thruster, this);
  lcm_subscription_set_queue_capacity(
      lcm_subscribe(lcm_, channels::kPlantTruth, &TestBus::on_truth, this), 1000);
}

TestBus::~TestBus() {
  if (lcm_ != nullptr) lcm_destroy(lcm_);
}

void TestBus::on_tlm(const lcm_recv_buf_t* rbuf, const char*, void* self) {
  auto& b = *static_cast<TestBus*>(self);
  rocksteady::gnc_telemetry_t m;
  if (wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), m)) {
    b.tlm = m;
    b.have_tlm = true;
    ++b.tlm_count;
    if (b.on_each_tlm) b.on_each_tlm(m);
  }
}
void TestBus::on_ack(const lcm_recv_buf_t* rbuf, const char*, void* self) {
  auto& b = *static_cast<TestBus*>(self);
  rocksteady::cmd_ack_t m;
  if (wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), m)) b.acks.push_back(m);
}
void TestBus::on_event(const lcm_recv_buf_t* rbuf, const char*, void* self) {
  auto& b = *static_cast<TestBus*>(self);
  rocksteady::event_t m;
  if (wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), m)) b.events.push_back(m);
}
void TestBus::on_truth(const lcm_recv_buf_t* rbuf, const char*, void* self) {
  auto& b = *static_cast<TestBus*>(self);
  rocksteady::plant_truth_t m;
  if (wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), m)) b.truths.push_back(m);
}
void TestBus::on_thruster(const lcm_recv_buf_t* rbuf, const char*, void* self) {
  auto& b = *static_cast<TestBus*>(self);
  rocksteady::thruster_cmd_t m;
  if (wire::safe_decode(rbuf->data, static_cast<int>(rbuf->data_size), m)) {
    b.thruster = m;
    b.have_thruster = true;
    ++b.thruster_count;
    for (int i = 0; i < 16; ++i) {
      if (m.thruster_on[i]) {
        ++b.thruster_firing_count;
        break;
      }
    }
  }
}

bool TestBus::spin_until(const std::function<bool()>& pred, double timeout_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!pred()) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= end) return false;
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(end - now).count();
    lcm_handle_timeout(lcm_, static_cast<int>(std::min<long long>(ms + 1, 20)));
  }
  return true;
}

void TestBus::spin_for(double seconds) {
  spin_until([] { return false; }, seconds);
}

void TestBus::send_command(std::int64_t seq, std::int32_t opcode, const std::vector<double>& args,
                           std::int32_t sender) {
  auto m = wire::make<rocksteady::ground_cmd_t>();
  m.seq = seq;
  m.sender_id = sender;
  m.opcode = opcode;
  m.nargs = static_cast<std::int8_t>(args.size());
  for (std::size_t i = 0; i < args.size() && i < 8; ++i) m.args[i] = args[i];
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  publish_raw(channels::kGroundCmd, buf);
}

void TestBus::publish_raw(const char* channel, const std::vector<std::uint8_t>& bytes) {
  lcm_publish(lcm_, channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
}

bool TestBus::has_event(std::int32_t id) const {
  for (const auto& e : events) {
    if (e.id == id) return true;
  }
  return false;
}

const rocksteady::cmd_ack_t* TestBus::ack_for(std::int64_t seq, std::int32_t sender) const {
  for (const auto& a : acks) {
    if (a.seq == seq && a.sender_id == sender) return &a;
  }
  return nullptr;
}

std::map<std::string, std::string> plant_summary(const std::string& text) {
  std::map<std::string, std::string> kv;
  const std::size_t at = text.find("summary: ");
  if (at == std::string::npos) return kv;
  const std::size_t end = text.find('\n', at);
  std::istringstream line(text.substr(at + 9, end - at - 9));
  std::string item;
  while (line >> item) {
    const std::size_t eq = item.find('=');
    if (eq != std::string::npos) kv[item.substr(0, eq)] = item.substr(eq + 1);
  }
  return kv;
}

}  // namespace rocksteady::pil
