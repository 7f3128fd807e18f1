// Command sequences (rocksteady-ground run SEQ.yaml, and the browser console's sequence form): a
// stored list of steps, each one of
//   - send: set-mode HOLD                      one command; waits for its acknowledgement
//   - wait: mode == HOLD, timeout 600 s        until fresh telemetry meets the condition
//   - sleep: 5 s                               a pause
// A condition is `POINT OP VALUE` on a point of the dictionary (RS_GNC_TLM by default, or
// CHANNEL.point), OP one of == != < <= > >=, VALUE a number or, for an enum point, a name (HOLD).
// The whole sequence is validated (every command encoded and checked as `send` does, every point,
// value and timeout) before the first command is sent; the run stops at the first rejection,
// missing acknowledgement or timeout, and the report says which step and why.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "ground/cli/command_gate.hpp"

namespace rocksteady::ground::cli {

struct Condition {
  enum class Op { kEq, kNe, kLt, kLe, kGt, kGe };
  std::string channel{"RS_GNC_TLM"};
  std::string point;
  int index{-1};  // in the channel's dictionary points
  Op op{Op::kEq};
  double value{0.0};
  std::string text;  // as written, for the report
};
bool holds(const Condition& c, double v);

struct Step {
  enum class Kind { kSend, kWait, kSleep };
  Kind kind{Kind::kSend};
  int line{0};       // in the file, 1-based
  std::string text;  // as written
  std::string command;
  std::vector<std::string> args;
  Condition condition;
  double timeout_s{0.0};
  double sleep_s{0.0};
};

struct Sequence {
  std::string name;
  std::vector<Step> steps;
};

struct SequenceParse {
  bool ok{false};
  Sequence sequence;
  std::vector<std::string> errors;  // "SEQ.yaml:4: step 2 (wait): unknown point 'mdoe' ..."
};

// Parses and validates completely. `source` names the text in messages (a file name).
SequenceParse parse_sequence(const std::string& yaml_text, const std::string& source);
SequenceParse load_sequence(const std::string& path);

struct SequenceReport {
  enum class Outcome { kCompleted, kAborted };
  Outcome outcome{Outcome::kAborted};
  int failed_step{-1};             // 1-based, when aborted
  std::vector<std::string> lines;  // one per step run
  std::string summary;
  std::string text() const;  // lines and summary
};

// Runs a validated sequence on `lcm` (used from this thread only). Progress lines go to `progress`
// (may be nullptr) as they happen.
SequenceReport run_sequence(const Sequence& sequence, CommandGate& gate, lcm::LCM& lcm,
                            std::FILE* progress);

}  // namespace rocksteady::ground::cli
