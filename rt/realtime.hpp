// Real-time hardening of a process (rocksteady-fsw, rocksteady-plant --mode realtime), applied once
// at start-up, before the bus is opened (threads created later, such as LCM's receive thread and
// the watchdog, inherit the policy, the affinity and the memory lock):
//
//   --cpu N            pin the process to CPU N (sched_setaffinity)
//   --mlockall         lock all current and future pages in RAM (mlockall MCL_CURRENT|MCL_FUTURE)
//   --prefault-stack B touch B bytes of stack now, so the tick never page-faults on its stack
//                      (default 256 KiB with --mlockall, else 0)
//   --sched-fifo PRIO  SCHED_FIFO at priority PRIO (1..99)
//   --rt-best-effort   a refused option is reported and skipped instead of ending the process
//
// Every requested option is reported on one line at start ("rt: ... applied" / "refused: reason").
// A refused option ends the process with kExitRealtimeRefused and a message naming the option, the
// system call, errno and what the system needs to permit it: never a silent downgrade, unless the
// operator asked for best effort explicitly.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace rocksteady::rt {

// Exit status of a process whose real-time options the system refused.
inline constexpr int kExitRealtimeRefused = 4;

struct RealtimeOptions {
  int fifo_priority{0};           // 0: not requested
  bool lock_memory{false};        // mlockall
  int cpu{-1};                    // -1: not requested
  long prefault_stack_bytes{-1};  // -1: the default (256 KiB with mlockall, else none)
  bool best_effort{false};

  bool any() const {
    return fifo_priority > 0 || lock_memory || cpu >= 0 || prefault_stack_bytes > 0;
  }
};

// Adds the options above to a CLI11 application.
void add_options(CLI::App& app, RealtimeOptions& options);

struct RealtimeResult {
  bool ok{true};                   // every requested option was applied
  std::vector<std::string> lines;  // one report line per requested option
  int fifo_priority_applied{0};    // 0 when SCHED_FIFO is not in effect
};

// Applies the options in a safe order (affinity, memory lock, stack, scheduling policy last) and
// reports each. With best_effort, a refused option is reported and the rest still applied;
// otherwise the first refusal stops (ok = false) and nothing further is attempted.
RealtimeResult apply(const RealtimeOptions& options);

// apply() plus the reporting convention of the Rocksteady processes: every line printed to `out`
// prefixed with `program`; on a refusal (without best effort) a final line saying the process
// exits. Returns 0, or kExitRealtimeRefused.
int apply_and_report(const RealtimeOptions& options, const char* program, std::FILE* out,
                     RealtimeResult* result = nullptr);

}  // namespace rocksteady::rt
