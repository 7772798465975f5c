#include "rigcal/view/http_routes.hpp"

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "static_assets.hpp"  // generated from view/assets

namespace rigcal::view {
namespace {

HttpReply reply(int status, std::string type, std::string body) { return HttpReply{status, std::move(type), std::move(body)}; }

/// One of three.js's installed files, by its fixed name (never a name from the request).
HttpReply threeFile(const char* relative) {
  const std::string path = threeJsDirectory() + "/" + relative;
  std::ifstream in(path, std::ios::binary);
  if (!in) return reply(404, "text/plain", std::string("three.js not installed (") + path + "): apt-get install libjs-three\n");
  std::ostringstream body;
  body << in.rdbuf();
  return reply(200, "application/javascript", body.str());
}

}  // namespace

std::string threeJsDirectory() {
  const char* dir = std::getenv("RIGCAL_THREE_DIR");
  return dir != nullptr && *dir != '\0' ? dir : "/usr/share/javascript/three";
}

HttpReply routeRequest(std::string_view method, std::string_view target, const std::string& report_json) {
  if (method != "GET" && method != "HEAD") return reply(405, "text/plain", "read-only: GET and HEAD only\n");
  const std::string_view path = target.substr(0, target.find('?'));
  if (path == "/" || path == "/index.html") return reply(200, "text/html; charset=utf-8", std::string(assets::kIndexHtml));
  if (path == "/view.js") return reply(200, "application/javascript", std::string(assets::kViewJs));
  if (path == "/view.css") return reply(200, "text/css", std::string(assets::kViewCss));
  if (path == "/three.min.js") return threeFile("three.min.js");
  if (path == "/OrbitControls.js") return threeFile("examples/js/controls/OrbitControls.js");
  if (path == "/report.json") {
    if (report_json.empty()) return reply(404, "text/plain", "no report yet: the run is still going\n");
    return reply(200, "application/json", report_json);
  }
  return reply(404, "text/plain", "not found\n");
}

}  // namespace rigcal::view
