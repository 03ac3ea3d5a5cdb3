// Wall-clock seconds for the statistics every stage reports (`seconds` fields).
#pragma once

#include <chrono>

namespace pic::detail {

using Clock = std::chrono::steady_clock;

/// Seconds from t0 to now.
inline double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace pic::detail
