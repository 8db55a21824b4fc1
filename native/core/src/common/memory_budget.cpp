#include "exsynth/memory_budget.hpp"

#include <cmath>
#include <cstdio>

#include "exsynth/errors.hpp"

namespace exsynth {

std::string format_bytes(double bytes) {
  if (!std::isfinite(bytes)) return "unboundedly many bytes";
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  int u = 0;
  while (bytes >= 1024.0 && u < 4) {
    bytes /= 1024.0;
    ++u;
  }
  char buf[48];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : bytes < 1e6 ? "%.2f %s" : "%.2g %s", bytes, units[u]);
  return buf;
}

std::string format_count(double count) {
  if (!std::isfinite(count)) return "infinitely many";
  char buf[48];
  std::snprintf(buf, sizeof buf, count < 1e15 ? "%.0f" : "%.2g", count);
  return buf;
}

void check_memory_budget(double bytes_needed, std::size_t budget, const std::string& job,
                         const std::string& advice) {
  if (budget == 0) budget = kDefaultMemoryBudget;
  if (bytes_needed > double(budget)) {
    throw OverBudget(job + " needs about " + format_bytes(bytes_needed) + ", over the memory budget of " +
                     format_bytes(double(budget)) + "; " + advice);
  }
}

}  // namespace exsynth
