#include "core/core_version.hpp"

namespace rr {

std::string_view core_version() noexcept { return "0.1.0"; }

}  // namespace rr
