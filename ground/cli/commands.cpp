#include "ground/cli/commands.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "gnc/math/rotation.hpp"
#include "gnc/param_bounds.hpp"
#include "ground/cli/dictionary.hpp"
#include "ground/dictionary/dictionary.hpp"

namespace rocksteady::ground::cli {

namespace {

using Msg = rocksteady::ground_cmd_t;

// The opcode table's ranges (fsw/commands/command_table.cpp) that the ground checks before sending.
constexpr double kIdMax = 2147483647.0;  // upload ids: int32 >= 0
constexpr double kValueMax = 1e30;       // parameter values
constexpr double kQuatNormTolerance = 1e-3;

const std::vector<CommandHelp> kHelp{
    {"noop", "noop", "no operation (link check); the flight answers with an ack"},
    {"set-mode", "set-mode IDLE|DETUMBLE|HOLD|TRACK|SAFE", "request a mode (next GNC tick)"},
    {"set-target", "set-target q1 q2 q3  |  set-target --quat x y z w",
     "HOLD/TRACK target attitude q_final as an MRP (|q| <= 1), or a unit quaternion, scalar last"},
    {"select-law",
     "select-law ntcl|el|integral|adaptive|so3|dpd|feedforward [keep|dpd-ref|fuel-optimal]",
     "select the control law and optionally the reference (dpd-ref: DETUMBLE/HOLD, fuel-optimal: "
     "TRACK)"},
    {"set-gain", "set-gain PARAM VALUES...",
     "load a parameter into the inactive table: a matrix takes 3 values (diagonal) or 6 (xx yy zz "
     "xy "
     "xz yz), a scalar 1, a flag 0|1; PARAM is a name (ntcl.K) or number (see 'params')"},
    {"activate-gains", "activate-gains", "the inactive table becomes active at the next GNC tick"},
    {"discard-gains", "discard-gains", "drop the loads: inactive table := active table"},
    {"dump-params", "dump-params",
     "read the active parameter table back on RS_PARAMS (params get prints it)"},
    {"load-identified", "load-identified",
     "load the flight's identified model (J_tot, r_SO/BCM, thruster strengths) into the inactive "
     "table; refused unless the identification is confident (activate-gains flies it)"},
    {"declare-fault", "declare-fault THRUSTER stuck-on|stuck-off|degraded [FACTOR]",
     "declare a thruster (0-15, 4 x pod + position) failed, or degraded to FACTOR (0.01-0.99) of "
     "its thrust; latched like a confirmed fault"},
    {"clear-fault", "clear-fault THRUSTER|all",
     "clear a thruster's declared or confirmed fault (valves are commanded separately)"},
    {"valve", "valve POD open|close", "command a pod's latch valve (0-3)"},
    {"isolation", "isolation inhibit|allow",
     "inhibit or allow the automatic closing of a valve on a confirmed stuck-on thruster"},
    {"reset-counters", "reset-counters",
     "reset the command/health counters (cycle counts are kept)"},
    {"load-trajectory", "load-trajectory UPLOAD_ID",
     "hand a completely uplinked trajectory to the flight core (in TRACK: switched to at the next "
     "tick boundary)"},
    {"abort-uplink", "abort-uplink UPLOAD_ID", "discard a trajectory uplink in progress"},
    {"key-rotate", "key-rotate KEY_ID",
     "make command key KEY_ID (higher than the active one) active at the next tick; then send "
     "with --key-id KEY_ID"},
    {"upload-trajectory", "upload-trajectory FILE",
     "uplink a planner trajectory file in chunks, wait for the flight to complete it, then load "
     "it"},
};

std::string join(const std::vector<std::string>& words, const char* sep) {
  std::string s;
  for (const std::string& w : words) {
    if (!s.empty()) s += sep;
    s += w;
  }
  return s;
}

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v + 0.0);  // + 0.0: no "-0"
  return buf;
}

Encoded fail(const std::string& message) {
  Encoded e;
  e.error = message;
  return e;
}

Encoded make(std::int32_t opcode, const std::vector<double>& args, const std::string& description) {
  Encoded e;
  e.ok = true;
  e.cmd.kind = Msg::KIND;
  e.cmd.version = Msg::VERSION;
  e.cmd.opcode = opcode;
  e.cmd.nargs = static_cast<std::int8_t>(args.size());
  for (std::size_t i = 0; i < args.size(); ++i) e.cmd.args[i] = args[i];
  e.description = description;
  return e;
}

const CommandHelp* find_help(const std::string& name) {
  for (const CommandHelp& h : kHelp) {
    if (name == h.name) return &h;
  }
  return nullptr;
}

// "set-mode takes 1 argument (usage: ...), got 2"
Encoded wrong_count(const std::string& name, const std::string& expected, std::size_t got) {
  const CommandHelp* h = find_help(name);
  return fail(name + " takes " + expected + ", got " + std::to_string(got) +
              (h != nullptr ? std::string(" (usage: ") + h->usage + ")" : std::string()));
}

// Parses every word as a number, or names the first that is not one.
bool numbers(const std::string& name, const std::vector<std::string>& words, std::size_t first,
             std::vector<double>& out, std::string& error) {
  out.clear();
  for (std::size_t i = first; i < words.size(); ++i) {
    double v = 0.0;
    if (!parse_number(words[i], v)) {
      error = name + ": argument " + std::to_string(i + 1) + " '" + words[i] +
              "' is not a finite number";
      return false;
    }
    out.push_back(v);
  }
  return true;
}

// An upload id: an integer in [0, 2^31 - 1].
bool upload_id(const std::string& name, const std::string& word, double& out, std::string& error) {
  if (!parse_number(word, out) || out < 0.0 || out > kIdMax || std::trunc(out) != out) {
    error = name + ": upload id '" + word + "' must be an integer in [0, 2147483647]";
    return false;
  }
  return true;
}

Encoded set_target(const std::vector<std::string>& args, const EncodeOptions& options) {
  const std::string name = "set-target";
  std::vector<double> v;
  std::string error;
  if (options.quaternion) {
    if (args.size() != 4)
      return wrong_count(name, "4 arguments with --quat (x y z w)", args.size());
    if (!numbers(name, args, 0, v, error)) return fail(error);
    const gnc::Vec4 beta(v[0], v[1], v[2], v[3]);
    const double n = beta.norm();
    if (std::abs(n - 1.0) > kQuatNormTolerance) {
      return fail(name + ": quaternion norm " + number_text(n) +
                  " is not 1 (a unit quaternion [x y z w], scalar last, is expected)");
    }
    const gnc::Vec3 q = gnc::mrp::from_quaternion(beta / n);  // the |q| <= 1 set
    return make(Msg::OP_SET_TARGET, {q.x(), q.y(), q.z()},
                "SET_TARGET q_final = [" + number_text(q.x()) + ", " + number_text(q.y()) + ", " +
                    number_text(q.z()) + "] (MRP, from quaternion)");
  }
  if (args.size() != 3) return wrong_count(name, "3 arguments (an MRP q1 q2 q3)", args.size());
  if (!numbers(name, args, 0, v, error)) return fail(error);
  const gnc::Vec3 q(v[0], v[1], v[2]);
  const double n2 = q.squaredNorm();
  if (q.norm() > 1.0) {
    const gnc::Vec3 s = gnc::mrp::shadow(q);
    return fail(name + ": MRP norm " + number_text(std::sqrt(n2)) +
                " is above 1; the same attitude in the |q| <= 1 set is [" + number_text(s.x()) +
                " " + number_text(s.y()) + " " + number_text(s.z()) + "]");
  }
  return make(Msg::OP_SET_TARGET, v,
              "SET_TARGET q_final = [" + number_text(v[0]) + ", " + number_text(v[1]) + ", " +
                  number_text(v[2]) + "] (MRP)");
}

Encoded select_law(const std::vector<std::string>& args) {
  const std::string name = "select-law";
  if (args.empty() || args.size() > 2) {
    return wrong_count(name, "1 or 2 arguments (law [reference])", args.size());
  }
  const auto law = law_from_name(args[0]);
  if (!law) {
    return fail(name + ": unknown law '" + args[0] + "' (one of " + join(law_names(), ", ") + ")");
  }
  std::vector<double> a{static_cast<double>(*law)};
  std::string description = std::string("SET_LAW ") + law_name(*law);
  if (args.size() == 2) {
    const auto ref = reference_from_name(args[1]);
    if (!ref) {
      return fail(name + ": unknown reference '" + args[1] +
                  "' (one of keep, dpd-ref, fuel-optimal)");
    }
    if (*law == 5 && *ref == 2) {
      return fail(name + ": the D+PD law cannot track the fuel-optimal reference");
    }
    a.push_back(static_cast<double>(*ref));
    description += std::string(" reference ") + reference_name(*ref);
  }
  return make(Msg::OP_SET_LAW, a, description);
}

Encoded set_gain(const std::vector<std::string>& args) {
  const std::string name = "set-gain";
  if (args.size() < 2) return wrong_count(name, "a parameter and its values", args.size());
  const auto p = find_param(args[0]);
  if (!p) {
    return fail(name + ": unknown parameter '" + args[0] +
                "' (a name such as ntcl.K or guidance.omega_switch, or a number 0.." +
                std::to_string(param_dictionary().size() - 1) + "; 'params' lists them)");
  }
  std::vector<double> values;
  std::string error;
  if (!numbers(name, args, 1, values, error)) return fail(error);
  const std::size_t n = values.size();
  switch (p->kind) {
    case ParamKind::kMatrix:
      if (n != 3 && n != 6) {
        return fail(name + ": " + p->name +
                    " is a matrix: 3 values (diagonal) or 6 (xx yy zz xy xz yz), got " +
                    std::to_string(n));
      }
      break;
    case ParamKind::kScalar:
      if (n != 1)
        return fail(name + ": " + p->name + " is a scalar: 1 value, got " + std::to_string(n));
      break;
    case ParamKind::kFlag:
      if (n != 1 || (values[0] != 0.0 && values[0] != 1.0)) {
        return fail(name + ": " + p->name + " is a flag: one value, 0 or 1");
      }
      break;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (std::abs(values[i]) > kValueMax) {
      return fail(name + ": value " + std::to_string(i + 1) + " is out of range (|v| <= 1e30)");
    }
  }
  // The flight's own physical ranges (gnc/param_bounds.cpp), checked before anything is sent.
  if (p->kind == ParamKind::kScalar && !gnc::within_bound(p->name, values[0])) {
    const gnc::ParamBound* b = gnc::find_param_bound(p->name);
    return fail(name + ": " + p->name + " = " + number_text(values[0]) +
                " is outside its physical range [" + number_text(b->lo) + ", " +
                number_text(b->hi) + "] " + b->units + ": " + b->why);
  }
  std::vector<double> a{static_cast<double>(p->id)};
  a.insert(a.end(), values.begin(), values.end());
  std::string description =
      std::string("PARAM_LOAD ") + p->name + " (" + std::to_string(p->id) + ") =";
  for (const double v : values) description += " " + number_text(v);
  return make(Msg::OP_PARAM_LOAD, a, description);
}

}  // namespace

bool parse_number(const std::string& word, double& out) {
  if (word.empty()) return false;
  const char* s = word.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s, &end);
  if (end == s || *end != '\0' || errno == ERANGE || !std::isfinite(v)) return false;
  // strtod also reads "inf", "nan" and hex floats; an operator's number is decimal.
  for (const char c : word) {
    if ((c < '0' || c > '9') && c != '.' && c != '-' && c != '+' && c != 'e' && c != 'E')
      return false;
  }
  out = v;
  return true;
}

Encoded encode_command(const std::string& name, const std::vector<std::string>& args,
                       const EncodeOptions& options) {
  if (options.quaternion && name != "set-target") {
    return fail("--quat applies to set-target only");
  }
  auto no_args = [&](std::int32_t op, const char* description) {
    if (!args.empty()) return wrong_count(name, "no arguments", args.size());
    return make(op, {}, description);
  };
  if (name == "noop") return no_args(Msg::OP_NOOP, "NOOP");
  if (name == "reset-counters") return no_args(Msg::OP_RESET_COUNTERS, "RESET_COUNTERS");
  if (name == "activate-gains") return no_args(Msg::OP_PARAM_ACTIVATE, "PARAM_ACTIVATE");
  if (name == "discard-gains") return no_args(Msg::OP_PARAM_DISCARD, "PARAM_DISCARD");
  if (name == "dump-params") return no_args(Msg::OP_PARAM_DUMP, "PARAM_DUMP");
  if (name == "load-identified") {
    return no_args(Msg::OP_PARAM_LOAD_IDENTIFIED, "PARAM_LOAD_IDENTIFIED");
  }
  auto index = [](const std::string& s, int lo, int hi, int& out) {
    try {
      std::size_t used = 0;
      const int v = std::stoi(s, &used);
      if (used != s.size() || v < lo || v > hi) return false;
      out = v;
      return true;
    } catch (const std::exception&) {
      return false;
    }
  };
  if (name == "declare-fault") {
    if (args.size() < 2 || args.size() > 3) return wrong_count(name, "2 or 3 arguments", args.size());
    int t = 0;
    if (!index(args[0], 0, 15, t)) return fail(name + ": thruster must be 0..15, got '" + args[0] + "'");
    if (args[1] != "stuck-on" && args[1] != "stuck-off" && args[1] != "degraded") {
      return fail(name + ": kind must be stuck-on, stuck-off or degraded, got '" + args[1] + "'");
    }
    if (args[1] == "degraded") {
      if (args.size() != 3) return fail(name + ": a degraded thruster needs its FACTOR (0.01-0.99)");
      double f = 0.0;
      try {
        std::size_t used = 0;
        f = std::stod(args[2], &used);
        if (used != args[2].size()) f = -1.0;
      } catch (const std::exception&) {
        f = -1.0;
      }
      if (!(f >= 0.01 && f <= 0.99)) {
        return fail(name + ": FACTOR must be a number in 0.01..0.99, got '" + args[2] + "'");
      }
      return make(Msg::OP_FAULT_DECLARE, {static_cast<double>(t), 3.0, f},
                  "FAULT_DECLARE thruster " + args[0] + " degraded x" + args[2]);
    }
    if (args.size() != 2) return fail(name + ": only a degraded thruster takes a FACTOR");
    const double kind = args[1] == "stuck-on" ? 1.0 : 2.0;
    return make(Msg::OP_FAULT_DECLARE, {static_cast<double>(t), kind},
                "FAULT_DECLARE thruster " + args[0] + " " + args[1]);
  }
  if (name == "clear-fault") {
    if (args.size() != 1) return wrong_count(name, "1 argument", args.size());
    int t = -1;
    if (args[0] != "all" && !index(args[0], 0, 15, t)) {
      return fail(name + ": thruster must be 0..15 or all, got '" + args[0] + "'");
    }
    return make(Msg::OP_FAULT_CLEAR, {static_cast<double>(t)}, "FAULT_CLEAR " + args[0]);
  }
  if (name == "valve") {
    if (args.size() != 2) return wrong_count(name, "2 arguments", args.size());
    int pod = 0;
    if (!index(args[0], 0, 3, pod)) return fail(name + ": pod must be 0..3, got '" + args[0] + "'");
    if (args[1] != "open" && args[1] != "close") {
      return fail(name + ": expected open or close, got '" + args[1] + "'");
    }
    return make(Msg::OP_VALVE, {static_cast<double>(pod), args[1] == "open" ? 1.0 : 0.0},
                "VALVE pod " + args[0] + " " + args[1]);
  }
  if (name == "isolation") {
    if (args.size() != 1) return wrong_count(name, "1 argument", args.size());
    if (args[0] != "inhibit" && args[0] != "allow") {
      return fail(name + ": expected inhibit or allow, got '" + args[0] + "'");
    }
    return make(Msg::OP_ISOLATION_INHIBIT, {args[0] == "inhibit" ? 1.0 : 0.0},
                "ISOLATION_INHIBIT " + args[0]);
  }
  if (name == "set-mode") {
    if (args.size() != 1) return wrong_count(name, "1 argument", args.size());
    const auto mode = mode_from_name(args[0]);
    if (!mode) {
      return fail(name + ": unknown mode '" + args[0] + "' (one of " + join(mode_names(), ", ") +
                  ")");
    }
    return make(Msg::OP_SET_MODE, {static_cast<double>(*mode)},
                std::string("SET_MODE ") + mode_name(*mode));
  }
  if (name == "set-target") return set_target(args, options);
  if (name == "select-law") return select_law(args);
  if (name == "set-gain") return set_gain(args);
  if (name == "load-trajectory" || name == "abort-uplink") {
    if (args.size() != 1) return wrong_count(name, "1 argument (the upload id)", args.size());
    double id = 0.0;
    std::string error;
    if (!upload_id(name, args[0], id, error)) return fail(error);
    const bool load = name == "load-trajectory";
    const std::int32_t op = load ? static_cast<std::int32_t>(Msg::OP_LOAD_TRAJECTORY)
                                 : static_cast<std::int32_t>(Msg::OP_ABORT_UPLINK);
    return make(op, {id}, std::string(load ? "LOAD_TRAJECTORY " : "ABORT_UPLINK ") + args[0]);
  }
  if (name == "key-rotate") {
    if (args.size() != 1) return wrong_count(name, "1 argument (the new key id)", args.size());
    double id = 0.0;
    if (!parse_number(args[0], id) || id < 1.0 || id > 2147483647.0 || std::trunc(id) != id) {
      return fail(name + ": the key id must be a positive integer, got '" + args[0] + "'");
    }
    return make(Msg::OP_KEY_ROTATE, {id}, "KEY_ROTATE " + args[0]);
  }
  if (name == "upload-trajectory") {
    return fail("upload-trajectory is a procedure of many messages, not one command");
  }
  return fail("unknown command '" + name + "' (one of " + command_list() + ")");
}

const std::vector<CommandHelp>& command_help() {
  return kHelp;
}

std::string command_list() {
  std::vector<std::string> names;
  for (const CommandHelp& h : kHelp) names.emplace_back(h.name);
  return join(names, ", ");
}

std::string opcode_name(int opcode) {
  if (auto n = dictionary::enum_name("opcode", opcode)) return *n;
  return "OP " + std::to_string(opcode);
}

void stamp(rocksteady::ground_cmd_t& cmd, std::int64_t seq, std::int32_t sender_id) {
  cmd.seq = seq;
  cmd.sender_id = sender_id;
}

}  // namespace rocksteady::ground::cli
