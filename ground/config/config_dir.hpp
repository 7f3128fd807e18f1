// Where the configuration files are, independently of the current directory, and what `--case N`
// means. Every ground tool resolves its configs here, so that they run from any directory, in the
// build tree and once installed.
//
// The configuration folder (the one holding mission.yaml, gnc.yaml and cases/) is the first of
//   1. the --config-dir the user gave,
//   2. $ROCKSTEADY_CONFIG_DIR,
//   3. <folder of the running program>/configs        (the build tree links it there),
//   4. <folder of the running program>/../share/rocksteady/configs   (cmake --install),
//   5. ./configs                                       (the repository root, as before).
#pragma once

#include <string>

namespace rocksteady::config {

struct ConfigDir {
  std::string path;   // "" when none was found
  std::string error;  // why not, naming the places tried
};

// `given`: the --config-dir option's value ("" when not given). A given folder must exist.
ConfigDir find_config_dir(const std::string& given = "");

// `--case` as typed: a number N means <config dir>/cases/caseN.yaml, anything else is a file
// path. Throws std::runtime_error naming `option` and the value when the file does not exist
// ("--case 9: no case file .../cases/case9.yaml (cases here: 1..7)").
std::string case_file(const std::string& config_dir, const std::string& value,
                      const std::string& option = "--case");

// mission.yaml / gnc.yaml of the folder; throws naming the file when it is missing.
std::string mission_file(const std::string& config_dir);
std::string gnc_file(const std::string& config_dir);

}  // namespace rocksteady::config
