#pragma once
// The view's HTTP routes: a fixed list of its own assets (embedded page, Debian's three.js) and the run's
// report. A request target is only ever compared with that list, never turned into a file-system path, so
// `/../etc/passwd` and friends are simply not found. Read-only: GET and HEAD only.
#include <string>
#include <string_view>

namespace rigcal::view {

struct HttpReply {
  int status = 200;
  std::string content_type;
  std::string body;
};

/// Where Debian's libjs-three installs three.js (three.min.js, examples/js/controls/OrbitControls.js).
/// $RIGCAL_THREE_DIR overrides it.
std::string threeJsDirectory();

/// The reply to `method target`. `report_json`: the finished run's report (empty while running).
HttpReply routeRequest(std::string_view method, std::string_view target, const std::string& report_json);

}  // namespace rigcal::view
