#pragma once
// Jobs estimate their peak memory before allocating and refuse to start when
// it exceeds the budget, so an over-large resolution fails fast with advice
// instead of exhausting the machine (and Blender with it).
#include <cstddef>
#include <cstdint>
#include <string>

namespace exsynth {

constexpr std::size_t kDefaultMemoryBudget = std::size_t(8) << 30;  // 8 GiB

/// "1.50 GiB", "12.0 MiB", ... for messages; any double (huge: "3.2e+21 TiB").
std::string format_bytes(double bytes);

/// A count for messages, computed in floating point so it saturates instead
/// of overflowing: "437361", "2.4e+19" (from 1e15 up), "infinitely many".
std::string format_count(double count);

/// Throws OverBudget when `bytes_needed` > `budget` (0 = kDefaultMemoryBudget).
/// `job` names the work ("voxelize at 2048 voxels"), `advice` what to change.
void check_memory_budget(double bytes_needed, std::size_t budget, const std::string& job,
                         const std::string& advice);

}  // namespace exsynth
