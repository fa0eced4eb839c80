// Where rr-gateway finds the dashboard's files by default.
#pragma once

#include <string>

namespace rr::server::app {

/// The dashboard folder. An installed binary (BIN/../share/rr-gateway exists, docs/deployment.md) uses
/// BIN/../share/rr-gateway/web, or none when it holds no index.html; a binary in a build tree uses
/// `web/dist` of the source tree it was built from, when built. BIN is the running executable's
/// folder (/proc/self/exe, so a binary found on PATH counts; `argv0` only when that cannot be read).
/// "" = no dashboard.
std::string default_web_root(const char* argv0);

}  // namespace rr::server::app
