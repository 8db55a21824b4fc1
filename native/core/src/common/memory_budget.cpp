#include "exsynth/memory_budget.hpp"

#include <cstdio>

#include "exsynth/errors.hpp"

namespace exsynth {

std::string format_bytes(double bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  int u = 0;
  while (bytes >= 1024.0 && u < 4) {
    bytes /= 1024.0;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.2f %s", bytes, units[u]);
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
