#include "rt/realtime.hpp"

#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <CLI/CLI.hpp>

namespace rocksteady::rt {

namespace {

constexpr long kDefaultPrefaultBytes = 256 * 1024;

std::string errno_text(int err) {
  return std::string(std::strerror(err)) + " (errno " + std::to_string(err) + ")";
}

std::string limit_text(int resource) {
  rlimit r{};
  if (getrlimit(resource, &r) != 0) return "unknown";
  const auto one = [](rlim_t v) {
    return v == RLIM_INFINITY ? std::string("unlimited")
                              : std::to_string(static_cast<unsigned long long>(v));
  };
  return one(r.rlim_cur) + "/" + one(r.rlim_max);
}

// Touches `bytes` of stack below this frame so the pages exist (and, after mlockall, stay).
__attribute__((noinline)) void touch_stack(long bytes) {
  constexpr long kChunk = 16 * 1024;
  volatile unsigned char block[kChunk];
  for (long i = 0; i < kChunk; i += 512) block[i] = 0;
  if (bytes > kChunk) touch_stack(bytes - kChunk);
  block[0] = block[kChunk - 1];
}

}  // namespace

void add_options(CLI::App& app, RealtimeOptions& o) {
  app.add_option("--sched-fifo", o.fifo_priority,
                 "real time: run under SCHED_FIFO at this priority (1..99)")
      ->check(CLI::Range(1, 99));
  app.add_flag("--mlockall", o.lock_memory, "lock all current and future memory (mlockall)");
  app.add_option("--cpu", o.cpu, "pin the process to this CPU (sched_setaffinity)")
      ->check(CLI::Range(0, 1 << 20));
  app.add_option("--prefault-stack", o.prefault_stack_bytes,
                 "touch this many bytes of stack at start (default 262144 with --mlockall)")
      ->check(CLI::Range(0L, 64L * 1024 * 1024));
  app.add_flag("--rt-best-effort", o.best_effort,
               "report a refused real-time option and continue without it (default: exit)");
}

RealtimeResult apply(const RealtimeOptions& o) {
  RealtimeResult r;
  const auto refuse = [&](const std::string& line) {
    r.ok = false;
    r.lines.push_back(line + (o.best_effort ? " -- continuing without it (--rt-best-effort)" : ""));
    return !o.best_effort;  // stop here?
  };

  if (o.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    const long online = sysconf(_SC_NPROCESSORS_ONLN);
    if (o.cpu >= CPU_SETSIZE) {
      if (refuse("--cpu " + std::to_string(o.cpu) + ": refused: CPU " + std::to_string(o.cpu) +
                 " is beyond CPU_SETSIZE (" + std::to_string(CPU_SETSIZE) + ")")) {
        return r;
      }
    } else {
      CPU_SET(static_cast<std::size_t>(o.cpu), &set);
      if (sched_setaffinity(0, sizeof set, &set) != 0) {
        const int err = errno;
        if (refuse("--cpu " + std::to_string(o.cpu) +
                   ": refused: sched_setaffinity: " + errno_text(err) + "; this machine has " +
                   std::to_string(online) + " CPUs online (0.." + std::to_string(online - 1) +
                   "), and the process may be confined to fewer (cgroup cpuset, taskset)")) {
          return r;
        }
      } else {
        r.lines.push_back("--cpu " + std::to_string(o.cpu) + ": applied (affinity: CPU " +
                          std::to_string(o.cpu) + " only)");
      }
    }
  }

  bool locked = false;
  if (o.lock_memory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
      const int err = errno;
      if (refuse("--mlockall: refused: mlockall(MCL_CURRENT|MCL_FUTURE): " + errno_text(err) +
                 "; needs CAP_IPC_LOCK or an RLIMIT_MEMLOCK above the process size (now " +
                 limit_text(RLIMIT_MEMLOCK) +
                 " bytes soft/hard; systemd: LimitMEMLOCK=infinity)")) {
        return r;
      }
    } else {
      locked = true;
      r.lines.push_back("--mlockall: applied (current and future pages locked)");
    }
  }

  const long prefault = o.prefault_stack_bytes >= 0 ? o.prefault_stack_bytes
                                                    : (o.lock_memory ? kDefaultPrefaultBytes : 0);
  if (prefault > 0) {
    rlimit st{};
    getrlimit(RLIMIT_STACK, &st);
    if (st.rlim_cur != RLIM_INFINITY && static_cast<rlim_t>(prefault) + 64 * 1024 > st.rlim_cur) {
      if (refuse("--prefault-stack " + std::to_string(prefault) + ": refused: the stack limit is " +
                 limit_text(RLIMIT_STACK) + " bytes; pre-faulting this much would overflow it")) {
        return r;
      }
    } else {
      touch_stack(prefault);
      r.lines.push_back("--prefault-stack: applied (" + std::to_string(prefault) +
                        " bytes of stack touched" + (locked ? " and locked)" : ", not locked)"));
    }
  }

  if (o.fifo_priority > 0) {
    sched_param sp{};
    sp.sched_priority = o.fifo_priority;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0) {
      const int err = errno;
      if (refuse("--sched-fifo " + std::to_string(o.fifo_priority) +
                 ": refused: sched_setscheduler(SCHED_FIFO): " + errno_text(err) +
                 "; needs CAP_SYS_NICE in the initial user namespace or an RLIMIT_RTPRIO of at "
                 "least " +
                 std::to_string(o.fifo_priority) + " (now " + limit_text(RLIMIT_RTPRIO) +
                 " soft/hard; systemd: LimitRTPRIO=), and a cgroup with real-time runtime")) {
        return r;
      }
    } else {
      r.fifo_priority_applied = o.fifo_priority;
      r.lines.push_back("--sched-fifo " + std::to_string(o.fifo_priority) +
                        ": applied (SCHED_FIFO priority " + std::to_string(o.fifo_priority) + ")");
    }
  }
  return r;
}

int apply_and_report(const RealtimeOptions& o, const char* program, std::FILE* out,
                     RealtimeResult* result) {
  RealtimeResult r = apply(o);
  if (!o.any()) r.lines.push_back("none requested (normal scheduling, memory not locked, any CPU)");
  for (const std::string& line : r.lines) std::fprintf(out, "%s: rt: %s\n", program, line.c_str());
  int rc = 0;
  if (!r.ok && !o.best_effort) {
    std::fprintf(out,
                 "%s: a requested real-time option was refused by the system; exiting (status %d). "
                 "Grant the permission, drop the option, or pass --rt-best-effort.\n",
                 program, kExitRealtimeRefused);
    rc = kExitRealtimeRefused;
  }
  std::fflush(out);
  if (result != nullptr) *result = std::move(r);
  return rc;
}

}  // namespace rocksteady::rt
