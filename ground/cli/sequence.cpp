#include "ground/cli/sequence.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include "ground/cli/commands.hpp"
#include "ground/dictionary/dictionary.hpp"

namespace rocksteady::ground::cli {

namespace {

using Clock = std::chrono::steady_clock;

std::vector<std::string> words(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// "600 s", "600", "1.5s": seconds > 0.
bool seconds(const std::string& s, double& out) {
  static const std::regex re(R"(^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*s?\s*$)");
  std::smatch m;
  if (!std::regex_match(s, m, re)) return false;
  out = std::stod(m[1]);
  return std::isfinite(out) && out > 0.0;
}

const char* op_text(Condition::Op op) {
  switch (op) {
    case Condition::Op::kEq:
      return "==";
    case Condition::Op::kNe:
      return "!=";
    case Condition::Op::kLt:
      return "<";
    case Condition::Op::kLe:
      return "<=";
    case Condition::Op::kGt:
      return ">";
    case Condition::Op::kGe:
      return ">=";
  }
  return "?";
}

// "mode == HOLD, timeout 600 s" -> condition and timeout, or an error message.
std::string parse_wait(const std::string& text, Step& step) {
  static const std::regex re(
      R"(^\s*([A-Za-z_][\w.]*)\s*(==|!=|<=|>=|<|>)\s*([^,]+?)\s*,\s*timeout\s+(.+)$)");
  std::smatch m;
  if (!std::regex_match(text, m, re)) {
    return "expected 'POINT OP VALUE, timeout N s' (e.g. 'mode == HOLD, timeout 600 s'), got '" +
           text + "'";
  }
  Condition& c = step.condition;
  c.text = text.substr(0, text.find(','));
  std::string point = m[1];
  if (const auto dot = point.find('.'); dot != std::string::npos) {
    c.channel = point.substr(0, dot);
    point = point.substr(dot + 1);
  }
  c.point = point;
  const dictionary::Channel* ch = dictionary::find_channel(c.channel);
  if (ch == nullptr) return "unknown channel '" + c.channel + "'";
  c.index = dictionary::find_point(*ch, point);
  if (c.index < 0) {
    return "unknown point '" + point + "' on " + c.channel +
           " (a field of the dictionary, e.g. mode, omega_hat_0, fuel_kg)";
  }
  const std::string op = m[2];
  const Condition::Op ops[] = {Condition::Op::kEq, Condition::Op::kNe, Condition::Op::kLt,
                               Condition::Op::kLe, Condition::Op::kGt, Condition::Op::kGe};
  for (Condition::Op o : ops) {
    if (op == op_text(o)) c.op = o;
  }
  const std::string value = m[3];
  const dictionary::Point& p = ch->points[c.index];
  if (!parse_number(value, c.value)) {
    const std::string en = p.enum_name;
    const auto v = en.empty() ? std::nullopt : dictionary::enum_value(en, value);
    if (!v) {
      std::string names;
      for (const std::string& n : dictionary::enum_names(en))
        names += (names.empty() ? "" : ", ") + n;
      return "'" + value + "' is not a number" +
             (en.empty() ? std::string() : " or a value of " + point + " (" + names + ")");
    }
    c.value = *v;
  }
  if (!seconds(m[4], step.timeout_s)) {
    return "timeout '" + std::string(m[4]) + "' must be a positive number of seconds";
  }
  return "";
}

std::string fmt_value(const Condition& c, double v) {
  const dictionary::Channel* ch = dictionary::find_channel(c.channel);
  return ch == nullptr ? std::to_string(v) : dictionary::format_value(ch->points[c.index], v);
}

// The newest values of each channel a wait looks at, and how many messages arrived.
class Watch {
 public:
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const dictionary::Channel* ch = dictionary::find_channel(channel);
    if (ch == nullptr) return;
    std::vector<double> v(static_cast<std::size_t>(ch->point_count));
    std::string text;
    wire::DecodeStatus st{};
    if (!ch->decode(rbuf->data, static_cast<int>(rbuf->data_size), v.data(), text, st)) return;
    Latest& l = latest_[channel];
    l.values = std::move(v);
    ++l.count;
  }
  struct Latest {
    std::vector<double> values;
    std::uint64_t count{0};
  };
  Latest get(const std::string& channel) const {
    const auto it = latest_.find(channel);
    return it == latest_.end() ? Latest{} : it->second;
  }

 private:
  std::map<std::string, Latest> latest_;
};

}  // namespace

bool holds(const Condition& c, double v) {
  switch (c.op) {
    case Condition::Op::kEq:
      return v == c.value;
    case Condition::Op::kNe:
      return v != c.value;
    case Condition::Op::kLt:
      return v < c.value;
    case Condition::Op::kLe:
      return v <= c.value;
    case Condition::Op::kGt:
      return v > c.value;
    case Condition::Op::kGe:
      return v >= c.value;
  }
  return false;
}

SequenceParse parse_sequence(const std::string& yaml_text, const std::string& source) {
  SequenceParse r;
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    r.errors.push_back(source + ":" + std::to_string(e.mark.line + 1) + ": not YAML: " + e.msg);
    return r;
  }
  if (!root.IsMap() || !root["steps"] || !root["steps"].IsSequence()) {
    r.errors.push_back(source + ": expected a map with 'steps:' (a list of send/wait/sleep)");
    return r;
  }
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    if (key != "name" && key != "steps") {
      r.errors.push_back(source + ":" + std::to_string(kv.first.Mark().line + 1) +
                         ": unknown key '" + key + "' (name, steps)");
    }
  }
  if (root["name"]) r.sequence.name = root["name"].as<std::string>();
  int n = 0;
  for (const YAML::Node& s : root["steps"]) {
    ++n;
    Step step;
    step.line = s.Mark().line + 1;
    const std::string where =
        source + ":" + std::to_string(step.line) + ": step " + std::to_string(n);
    if (!s.IsMap() || s.size() != 1) {
      r.errors.push_back(where + ": must be one of 'send: ...', 'wait: ...', 'sleep: ...'");
      continue;
    }
    const std::string kind = s.begin()->first.as<std::string>();
    if (!s.begin()->second.IsScalar()) {
      r.errors.push_back(where + " (" + kind + "): the value must be text");
      continue;
    }
    step.text = s.begin()->second.as<std::string>();
    std::string error;
    if (kind == "send") {
      step.kind = Step::Kind::kSend;
      const std::vector<std::string> w = words(step.text);
      if (w.empty()) {
        error = "no command";
      } else {
        step.command = w[0];
        step.args.assign(w.begin() + 1, w.end());
        error = CommandGate::check(step.command, step.args);
      }
    } else if (kind == "wait") {
      step.kind = Step::Kind::kWait;
      error = parse_wait(step.text, step);
    } else if (kind == "sleep") {
      step.kind = Step::Kind::kSleep;
      if (!seconds(step.text, step.sleep_s))
        error = "'" + step.text + "' is not a positive number of seconds";
    } else {
      error = "unknown step '" + kind + "' (send, wait, sleep)";
    }
    if (!error.empty()) {
      r.errors.push_back(where + " (" + kind + "): " + error);
      continue;
    }
    r.sequence.steps.push_back(step);
  }
  if (n == 0) r.errors.push_back(source + ": 'steps' is empty");
  r.ok = r.errors.empty();
  return r;
}

SequenceParse load_sequence(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    SequenceParse r;
    r.errors.push_back(path + ": cannot read file");
    return r;
  }
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_sequence(ss.str(), path);
}

std::string SequenceReport::text() const {
  std::string s;
  for (const std::string& l : lines) s += l + "\n";
  return s + summary + "\n";
}

SequenceReport run_sequence(const Sequence& sequence, CommandGate& gate, lcm::LCM& lcm,
                            std::FILE* progress) {
  SequenceReport report;
  Watch watch;
  std::vector<lcm::Subscription*> subs;
  for (const dictionary::Channel& c : dictionary::channels()) {
    if (std::string(c.channel) == "RS_GNC_TLM" || std::string(c.channel) == "RS_PLANT_TRUTH") {
      subs.push_back(lcm.subscribe(c.channel, &Watch::on_message, &watch));
    }
  }
  const auto say = [&](const std::string& line) {
    report.lines.push_back(line);
    if (progress != nullptr) {
      std::fprintf(progress, "%s\n", line.c_str());
      std::fflush(progress);
    }
  };
  const auto seconds_since = [](Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  const int total = static_cast<int>(sequence.steps.size());
  const Clock::time_point start = Clock::now();
  int i = 0;
  bool failed = false;
  for (const Step& step : sequence.steps) {
    ++i;
    const std::string head = "step " + std::to_string(i) + "/" + std::to_string(total) + " (line " +
                             std::to_string(step.line) + ") ";
    const Clock::time_point t0 = Clock::now();
    char elapsed[32];
    if (step.kind == Step::Kind::kSend) {
      const GateResult g = gate.send(step.command, step.args, &lcm);
      std::snprintf(elapsed, sizeof elapsed, "%.1f", seconds_since(t0));
      say(head + "send " + step.text + ": " + g.description + " seq " + std::to_string(g.seq) +
          ": " + (g.outcome == GateResult::Outcome::kAccepted ? "ACCEPTED" : g.message));
      if (g.outcome != GateResult::Outcome::kAccepted) {
        failed = true;
        report.summary = std::string("ABORTED at step ") + std::to_string(i) + " (line " +
                         std::to_string(step.line) + "): " + step.text + " was " +
                         to_string(g.outcome) + ": " + g.message;
      }
    } else if (step.kind == Step::Kind::kSleep) {
      const Clock::time_point until = t0 + std::chrono::duration_cast<Clock::duration>(
                                               std::chrono::duration<double>(step.sleep_s));
      while (Clock::now() < until) {
        const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now());
        lcm.handleTimeout(
            static_cast<int>(std::max<long long>(1, std::min<long long>(ms.count(), 100))));
      }
      say(head + "sleep " + step.text + ": done");
    } else {
      const Condition& c = step.condition;
      // Only telemetry that arrives after the step starts counts: no verdict on old data.
      const std::uint64_t before = watch.get(c.channel).count;
      bool met = false;
      double last = std::nan("");
      std::uint64_t seen = 0;
      while (seconds_since(t0) < step.timeout_s) {
        lcm.handleTimeout(100);
        const Watch::Latest l = watch.get(c.channel);
        if (l.count > before) {
          seen = l.count - before;
          last = l.values[static_cast<std::size_t>(c.index)];
          if (holds(c, last)) {
            met = true;
            break;
          }
        }
      }
      std::snprintf(elapsed, sizeof elapsed, "%.1f", seconds_since(t0));
      if (met) {
        say(head + "wait " + c.text + ": met after " + elapsed + " s (" + c.point + " = " +
            fmt_value(c, last) + ")");
      } else {
        const std::string why = seen == 0 ? "no " + c.channel + " telemetry arrived"
                                          : "last " + c.point + " = " + fmt_value(c, last);
        say(head + "wait " + c.text + ": TIMEOUT after " + elapsed + " s (" + why + ")");
        failed = true;
        report.summary = "ABORTED at step " + std::to_string(i) + " (line " +
                         std::to_string(step.line) + "): " + c.text + " not met within " + elapsed +
                         " s (" + why + ")";
      }
    }
    if (failed) break;
  }
  for (lcm::Subscription* s : subs) {
    if (s != nullptr) lcm.unsubscribe(s);
  }
  char took[32];
  std::snprintf(took, sizeof took, "%.1f", seconds_since(start));
  if (failed) {
    report.outcome = SequenceReport::Outcome::kAborted;
    report.failed_step = i;
    report.summary += "; steps after it were not run";
  } else {
    report.outcome = SequenceReport::Outcome::kCompleted;
    report.summary = "COMPLETED: " + std::to_string(total) + " steps of '" +
                     (sequence.name.empty() ? std::string("sequence") : sequence.name) + "' in " +
                     took + " s";
  }
  if (progress != nullptr) {
    std::fprintf(progress, "%s\n", report.summary.c_str());
    std::fflush(progress);
  }
  return report;
}

}  // namespace rocksteady::ground::cli
