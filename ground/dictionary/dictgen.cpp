// rocksteady-dictgen: builds the ground's telemetry/command dictionary at build time from
//   - lcmtypes/*.lcm (every field of every bus type, in .lcm order, with its array dimensions),
//   - ground/dictionary/dictionary.yaml (units, yellow/red limits, enums, event severities),
//   - the flight application's own tables (opcode, reject-reason and event names: fsw::to_string).
// It refuses (exit 2, naming file, key and reason) a field without an entry, an entry without a
// field, an unknown enum, a malformed limit, an event without a severity or a severity for an event
// the flight does not define. It writes
//   dictionary.json            for the ground server and the browser console, and
//   dictionary_generated.cpp   the same tables for C++, plus one decode-and-flatten function per
//                              bus type (safe_decode, then every numeric element in .lcm order).
// Usage: rocksteady-dictgen DICTIONARY.yaml OUT_DIR LCMFILE...
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "fsw/interface.hpp"

namespace {

using nlohmann::json;

struct LcmField {
  std::string type;  // int8_t .. double, boolean, byte, string
  std::string name;
  std::vector<int> dims;
};

struct LcmType {
  std::string name;
  std::string file;
  std::vector<LcmField> fields;
};

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw std::runtime_error(where + ": " + what);
}

LcmType parse_lcm(const std::string& path) {
  std::ifstream in(path);
  if (!in) fail(path, "cannot read file");
  LcmType t;
  t.file = path;
  const std::regex struct_re(R"(^\s*struct\s+(\w+))");
  const std::regex field_re(R"(^\s*(\w+)\s+(\w+)((?:\s*\[\s*\d+\s*\])*)\s*;)");
  const std::regex dim_re(R"(\[\s*(\d+)\s*\])");
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string code = line.substr(0, line.find("//"));
    std::smatch m;
    if (std::regex_search(code, m, struct_re)) {
      t.name = m[1];
      continue;
    }
    if (code.find("const ") != std::string::npos || code.find("package") != std::string::npos) {
      continue;
    }
    if (std::regex_search(code, m, field_re)) {
      LcmField f;
      f.type = m[1];
      f.name = m[2];
      const std::string dims = m[3];
      for (auto it = std::sregex_iterator(dims.begin(), dims.end(), dim_re);
           it != std::sregex_iterator(); ++it) {
        f.dims.push_back(std::stoi((*it)[1]));
      }
      static const std::set<std::string> kTypes{"int8_t", "int16_t", "int32_t", "int64_t", "float",
                                                "double", "boolean", "byte",    "string"};
      if (kTypes.count(f.type) == 0) {
        fail(path + ":" + std::to_string(line_no), "field '" + f.name + "' has type '" + f.type +
                                                       "', which the dictionary does not handle");
      }
      t.fields.push_back(f);
    }
  }
  if (t.name.empty()) fail(path, "no struct found");
  return t;
}

// The element keys of a field: name, name_0.., name_i_j (the CSV column names of log2csv).
std::vector<std::pair<std::string, std::string>> element_keys(const LcmField& f) {
  std::vector<std::pair<std::string, std::string>> keys;  // key, C++ access
  if (f.dims.empty()) {
    keys.emplace_back(f.name, "m." + f.name);
  } else if (f.dims.size() == 1) {
    for (int i = 0; i < f.dims[0]; ++i) {
      keys.emplace_back(f.name + "_" + std::to_string(i),
                        "m." + f.name + "[" + std::to_string(i) + "]");
    }
  } else if (f.dims.size() == 2) {
    for (int i = 0; i < f.dims[0]; ++i) {
      for (int j = 0; j < f.dims[1]; ++j) {
        keys.emplace_back(f.name + "_" + std::to_string(i) + "_" + std::to_string(j),
                          "m." + f.name + "[" + std::to_string(i) + "][" + std::to_string(j) + "]");
      }
    }
  } else {
    fail(f.name, "arrays of more than two dimensions are not supported");
  }
  return keys;
}

struct Limit {
  bool has_lo{false}, has_hi{false};
  double lo{0.0}, hi{0.0};
};

Limit read_limit(const YAML::Node& n, const std::string& where) {
  Limit l;
  if (!n) return l;
  if (!n.IsSequence() || n.size() != 2) fail(where, "must be [low, high] (null for no bound)");
  for (int i = 0; i < 2; ++i) {
    const YAML::Node b = n[static_cast<std::size_t>(i)];
    if (b.IsNull()) continue;
    double v = 0.0;
    try {
      v = b.as<double>();
    } catch (const YAML::Exception&) {
      fail(where, "bound " + std::to_string(i) + " '" + b.Scalar() + "' is not a number or null");
    }
    if (!std::isfinite(v)) fail(where, "bound " + std::to_string(i) + " is not finite");
    (i == 0 ? l.has_lo : l.has_hi) = true;
    (i == 0 ? l.lo : l.hi) = v;
  }
  if (l.has_lo && l.has_hi && l.lo >= l.hi) fail(where, "low bound must be below the high bound");
  return l;
}

json limit_json(const Limit& l) {
  if (!l.has_lo && !l.has_hi) return nullptr;
  return json::array(
      {l.has_lo ? json(l.lo) : json(nullptr), l.has_hi ? json(l.hi) : json(nullptr)});
}

std::string cpp_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string cpp_double(bool has, double v, bool low) {
  if (!has) return low ? "-kInf" : "kInf";
  std::ostringstream o;
  o.precision(17);
  o << v;
  std::string s = o.str();
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

int run(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: rocksteady-dictgen DICTIONARY.yaml OUT_DIR LCMFILE...\n");
    return 2;
  }
  const std::string yaml_path = argv[1];
  const std::string out_dir = argv[2];
  std::vector<LcmType> types;
  for (int i = 3; i < argc; ++i) types.push_back(parse_lcm(argv[i]));

  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::Exception& e) {
    fail(yaml_path, std::string("cannot parse: ") + e.what());
  }

  // --- Enums: the dictionary's own, then the flight's tables ---------------------------------
  std::map<std::string, std::map<int, std::string>> enums;
  if (!root["enums"] || !root["enums"].IsMap()) fail(yaml_path, "enums: missing or not a map");
  for (const auto& e : root["enums"]) {
    const std::string name = e.first.as<std::string>();
    if (!e.second.IsSequence()) fail(yaml_path, "enums." + name + ": must be a list of names");
    int i = 0;
    for (const auto& v : e.second) enums[name][i++] = v.as<std::string>();
  }
  using rocksteady::fsw::EventId;
  using rocksteady::fsw::Opcode;
  using rocksteady::fsw::RejectReason;
  using rocksteady::fsw::to_string;
  for (int i = 0; i < 256; ++i) {
    const std::string n = to_string(static_cast<Opcode>(i));
    if (n != "?") enums["opcode"][i] = n;
  }
  for (int i = 0; i < 256; ++i) {
    const std::string n = to_string(static_cast<RejectReason>(i));
    if (n != "?") enums["reason"][i] = n;
  }
  for (int i = 0; i < 4096; ++i) {
    const std::string n = to_string(static_cast<EventId>(i));
    if (n != "?") enums["event"][i] = n;
  }
  if (enums["opcode"].size() != static_cast<std::size_t>(rocksteady::fsw::kOpcodeCount)) {
    fail("fsw::to_string(Opcode)", "names " + std::to_string(enums["opcode"].size()) +
                                       " opcodes, kOpcodeCount is " +
                                       std::to_string(rocksteady::fsw::kOpcodeCount));
  }

  // --- Event severities: exactly the flight's events -----------------------------------------
  const YAML::Node ev = root["events"];
  if (!ev || !ev.IsMap()) fail(yaml_path, "events: missing or not a map");
  std::map<std::string, std::string> severity_of;
  for (const auto& e : ev) {
    const std::string name = e.first.as<std::string>();
    const std::string sev = e.second.as<std::string>();
    bool known_sev = false;
    for (const auto& [i, s] : enums["severity"]) known_sev = known_sev || s == sev;
    if (!known_sev)
      fail(yaml_path, "events." + name + ": severity '" + sev + "' is not one of enums.severity");
    severity_of[name] = sev;
  }
  json events = json::array();
  for (const auto& [id, name] : enums["event"]) {
    if (severity_of.count(name) == 0) {
      fail(yaml_path, "events: the flight's event '" + name + "' (" + std::to_string(id) +
                          ") has no severity");
    }
    events.push_back({{"id", id}, {"name", name}, {"severity", severity_of[name]}});
    severity_of.erase(name);
  }
  if (!severity_of.empty()) {
    fail(yaml_path, "events." + severity_of.begin()->first + ": the flight defines no such event");
  }
  if (const YAML::Node pe = root["plant_events"]) {
    if (!pe.IsMap()) fail(yaml_path, "plant_events: must map ids to [name, severity]");
    for (const auto& e : pe) {
      const std::string where = "plant_events." + e.first.as<std::string>();
      int id = 0;
      try {
        id = e.first.as<int>();
      } catch (const YAML::Exception&) {
        fail(yaml_path, where + ": the id must be an integer");
      }
      if (id < 1000) fail(yaml_path, where + ": plant event ids start at 1000");
      if (!e.second.IsSequence() || e.second.size() != 2)
        fail(yaml_path, where + ": must be [name, severity]");
      const std::string name = e.second[0].as<std::string>();
      const std::string sev = e.second[1].as<std::string>();
      bool known_sev = false;
      for (const auto& [i, s] : enums["severity"]) known_sev = known_sev || s == sev;
      if (!known_sev)
        fail(yaml_path, where + ": severity '" + sev + "' is not one of enums.severity");
      if (enums["event"].count(id) != 0) fail(yaml_path, where + ": the id is the flight's");
      enums["event"][id] = name;
      events.push_back({{"id", id}, {"name", name}, {"severity", sev}});
    }
  }

  // --- Channels: every field of every type, and nothing else ----------------------------------
  const YAML::Node ty = root["types"];
  if (!ty || !ty.IsMap()) fail(yaml_path, "types: missing or not a map");
  std::set<std::string> type_names;
  for (const LcmType& t : types) type_names.insert(t.name);
  for (const auto& e : ty) {
    if (type_names.count(e.first.as<std::string>()) == 0) {
      fail(yaml_path, "types." + e.first.as<std::string>() + ": no such type in lcmtypes/");
    }
  }

  json channels = json::array();
  std::ostringstream tables;    // C++ point tables
  std::ostringstream decoders;  // C++ decode functions
  std::ostringstream chan_list;
  for (const LcmType& t : types) {
    const YAML::Node tn = ty[t.name];
    const std::string tw = "types." + t.name;
    if (!tn) fail(yaml_path, tw + ": missing (every bus type needs an entry; " + t.file + ")");
    if (!tn["channel"]) fail(yaml_path, tw + ".channel: missing");
    const std::string channel = tn["channel"].as<std::string>();
    const std::string title = tn["title"] ? tn["title"].as<std::string>() : t.name;
    bool periodic = false;
    if (tn["periodic"]) {
      try {
        periodic = tn["periodic"].as<bool>();
      } catch (const YAML::Exception&) {
        fail(yaml_path, tw + ".periodic: must be true or false");
      }
    }
    const YAML::Node fields = tn["fields"];
    if (!fields || !fields.IsMap()) fail(yaml_path, tw + ".fields: missing or not a map");
    std::set<std::string> lcm_fields;
    for (const LcmField& f : t.fields) lcm_fields.insert(f.name);
    for (const auto& e : fields) {
      if (lcm_fields.count(e.first.as<std::string>()) == 0) {
        fail(yaml_path, tw + ".fields." + e.first.as<std::string>() + ": " + t.name +
                            " has no such field (" + t.file + ")");
      }
    }
    json points = json::array();
    json text_fields = json::array();
    std::string body;
    tables << "const Point k" << t.name << "Points[] = {\n";
    int count = 0;
    for (const LcmField& f : t.fields) {
      const std::string fw = tw + ".fields." + f.name;
      const YAML::Node fn = fields[f.name];
      if (!fn) fail(yaml_path, fw + ": missing (field of " + t.file + ")");
      if (!fn["units"]) fail(yaml_path, fw + ".units: missing (\"\" for none)");
      const std::string units = fn["units"].as<std::string>();
      const std::string description = fn["description"] ? fn["description"].as<std::string>() : "";
      const std::string en = fn["enum"] ? fn["enum"].as<std::string>() : "";
      if (!en.empty() && enums.count(en) == 0)
        fail(yaml_path, fw + ".enum: unknown enum '" + en + "'");
      const Limit yellow = read_limit(fn["yellow"], yaml_path + ": " + fw + ".yellow");
      const Limit red = read_limit(fn["red"], yaml_path + ": " + fw + ".red");
      if (f.type == "string") {
        if (fn["yellow"] || fn["red"] || !en.empty())
          fail(yaml_path, fw + ": a text field has no limits or enum");
        text_fields.push_back(f.name);
        body += "  text = m." + f.name + ";\n";
        continue;
      }
      for (const auto& [key, access] : element_keys(f)) {
        json p = {{"key", key}, {"field", f.name}, {"units", units}};
        if (!description.empty()) p["description"] = description;
        if (!en.empty()) p["enum"] = en;
        if (yellow.has_lo || yellow.has_hi) p["yellow"] = limit_json(yellow);
        if (red.has_lo || red.has_hi) p["red"] = limit_json(red);
        p["format"] = (f.type == "double" || f.type == "float") ? "float" : "integer";
        points.push_back(p);
        tables << "    {" << cpp_string(key) << ", " << cpp_string(f.name) << ", "
               << cpp_string(units) << ", " << cpp_string(en) << ", "
               << cpp_double(yellow.has_lo, yellow.lo, true) << ", "
               << cpp_double(yellow.has_hi, yellow.hi, false) << ", "
               << cpp_double(red.has_lo, red.lo, true) << ", "
               << cpp_double(red.has_hi, red.hi, false) << "},\n";
        body += "  out[" + std::to_string(count) + "] = static_cast<double>(" + access + ");\n";
        ++count;
      }
    }
    tables << "};\n";
    decoders << "bool decode_" << t.name
             << "(const void* data, int len, double* out, std::string& text, "
                "wire::DecodeStatus& status) {\n"
             << "  rocksteady::" << t.name << " m;\n"
             << "  status = wire::decode(data, len, m);\n"
             << "  if (status != wire::DecodeStatus::kOk) return false;\n"
             << "  (void)text;\n"
             << body << "  return true;\n}\n";
    chan_list << "      {" << cpp_string(channel) << ", " << cpp_string(t.name) << ", "
              << cpp_string(title) << ", k" << t.name << "Points, " << count << ", &decode_"
              << t.name << ", " << (text_fields.empty() ? "false" : "true") << "},\n";
    channels.push_back({{"channel", channel},
                        {"type", t.name},
                        {"title", title},
                        {"periodic", periodic},
                        {"points", points},
                        {"text_fields", text_fields}});
  }

  json enum_json = json::object();
  for (const auto& [name, values] : enums) {
    json v = json::array();
    for (const auto& [i, n] : values) v.push_back({{"value", i}, {"name", n}});
    enum_json[name] = v;
  }
  const json dict = {
      {"name", "Rocksteady"}, {"enums", enum_json}, {"events", events}, {"channels", channels}};

  const std::string json_path = out_dir + "/dictionary.json";
  std::ofstream jout(json_path, std::ios::trunc);
  if (!jout) fail(json_path, "cannot write");
  jout << dict.dump(1) << "\n";

  std::ostringstream enum_tables;
  for (const auto& [name, values] : enums) {
    enum_tables << "      {" << cpp_string(name) << ", {";
    for (const auto& [i, n] : values) enum_tables << "{" << i << ", " << cpp_string(n) << "}, ";
    enum_tables << "}},\n";
  }
  std::ostringstream event_table;
  for (const auto& e : events) {
    event_table << "      {" << e["id"].get<int>() << ", "
                << cpp_string(e["name"].get<std::string>()) << ", "
                << cpp_string(e["severity"].get<std::string>()) << "},\n";
  }

  const std::string cpp_path = out_dir + "/dictionary_generated.cpp";
  std::ofstream cout(cpp_path, std::ios::trunc);
  if (!cout) fail(cpp_path, "cannot write");
  cout << "// Generated by rocksteady-dictgen from ground/dictionary/dictionary.yaml, "
          "lcmtypes/*.lcm\n"
          "// and the flight's tables. Do not edit.\n"
          "#include <limits>\n#include <string>\n\n"
          "#include \"ground/dictionary/dictionary.hpp\"\n#include \"wire/codec.hpp\"\n\n"
          "namespace rocksteady::ground::dictionary {\nnamespace {\n"
          "constexpr double kInf = std::numeric_limits<double>::infinity();\n"
       << tables.str() << decoders.str() << "}  // namespace\n\n"
       << "namespace generated {\n"
          "const std::vector<Channel>& channels() {\n  static const std::vector<Channel> c{\n"
       << chan_list.str() << "  };\n  return c;\n}\n"
       << "const std::map<std::string, std::map<int, std::string>>& enums() {\n"
          "  static const std::map<std::string, std::map<int, std::string>> e{\n"
       << enum_tables.str() << "  };\n  return e;\n}\n"
       << "const std::vector<EventInfo>& events() {\n  static const std::vector<EventInfo> e{\n"
       << event_table.str() << "  };\n  return e;\n}\n"
       << "const std::string& json_text() {\n  static const std::string j = R\"RSDICT("
       << dict.dump() << ")RSDICT\";\n  return j;\n}\n"
       << "}  // namespace generated\n}  // namespace rocksteady::ground::dictionary\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rocksteady-dictgen: %s\n", e.what());
    return 2;
  }
}
