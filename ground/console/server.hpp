// rocksteady-ground serve: the ground server of the browser console (ground/console/README.md).
// It bridges the LCM bus to the browser over HTTP (cpp-httplib):
//   GET  /                      the Open MCT application (web root: app/ and openmct/)
//   GET  /api/dictionary        the generated dictionary (channels, points, units, limits, enums)
//   GET  /api/history?channel=C&key=K&start=MS&end=MS   [[utc_ms, value], ...]
//   GET  /api/latest            every channel's newest sample, reception statistics
//   GET  /api/events?after=N    events with names and severities
//   GET  /api/stream            Server-Sent Events: new samples, events and channel ages, 4 per s
//   GET  /api/commands          the command words and their usage (the form's choices)
//   POST /api/command           {"command": "set-mode", "args": ["HOLD"]}: encoded and checked as
//                               `rocksteady-ground send` does, sent, and answered with the flight's
//                               acknowledgement (accepted, or the reason it was rejected)
//   POST /api/sequence          a command sequence (YAML, as for `rocksteady-ground run`):
//                               validated completely, then run; the report
// It listens on loopback unless told otherwise.
#pragma once

#include <string>

namespace rocksteady::ground::console {

struct ServeOptions {
  std::string bind{"127.0.0.1"};
  int port{8090};         // 0: any free port (printed)
  std::string web_root;   // holds app/index.html and openmct/openmct.js
  std::string lcm_url;    // "" = LCM's default ($LCM_DEFAULT_URL)
  int sender{2};          // sender id of the console's commands
  std::string state_dir;  // sequence-number state ("" = the CLI's default)
  double ack_timeout_s{3.0};
  double stale_after_s{3.0};  // a channel is stale after this long without a message
};

// The web root next to the program: $ROCKSTEADY_CONSOLE_WEB, else <exe dir>/console-web (build
// tree), else <exe dir>/../share/rocksteady/console-web (installed). "" if none has the app.
std::string find_web_root();

// Runs until SIGINT or SIGTERM. Returns 0, or 2 when the bus or the port cannot be opened.
int serve(const ServeOptions& options);

}  // namespace rocksteady::ground::console
