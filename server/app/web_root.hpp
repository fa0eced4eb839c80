// Where rr-gateway finds the dashboard's files by default.
#pragma once

#include <string>

namespace rr::server::app {

/// The dashboard folder: `web/dist` of the source tree the binary was built from, when it exists.
std::string default_web_root(const char* argv0);

}  // namespace rr::server::app
