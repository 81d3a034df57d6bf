#include "common/util/memory_limit.h"

#include <unistd.h>

#include <atomic>
#include <charconv>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "common/util/error.h"

namespace pr {

namespace {
std::atomic<uint64_t> gLimit{0};  // 0 = not set: defaultMemoryLimit()
}

uint64_t physicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && pageSize > 0 ? uint64_t(pages) * uint64_t(pageSize) : 0;
}

uint64_t defaultMemoryLimit() {
  const uint64_t physical = physicalMemoryBytes();
  return physical > 0 ? physical / 4 * 3 : uint64_t(4) << 30;
}

uint64_t parseByteSize(std::string_view text, std::string_view option) {
  auto bad = [&] {
    return InputError((option.empty() ? std::string() : std::string(option) + ": ") + "'" + std::string(text) +
                      "' is not a size (expected a positive number of bytes with an optional K, M, G or T suffix, e.g. 512M or 2G)");
  };
  size_t end = 0;
  while (end < text.size() && (std::isdigit(static_cast<unsigned char>(text[end])) || text[end] == '.')) ++end;
  if (end == 0) throw bad();
  double value = 0.0;
  const auto [parsed, error] = std::from_chars(text.data(), text.data() + end, value, std::chars_format::fixed);
  if (error != std::errc() || parsed != text.data() + end) throw bad();  // "1.2.3"
  std::string suffix(text.substr(end));
  for (char& c : suffix) c = char(std::toupper(static_cast<unsigned char>(c)));
  if (suffix.size() > 1 && suffix.back() == 'B') suffix.pop_back();  // "GB", "GIB" -> "G", "GI"
  if (suffix.size() == 2 && suffix[1] == 'I') suffix.pop_back();
  double scale = 1.0;
  if (suffix == "K") scale = 0x1p10;
  else if (suffix == "M") scale = 0x1p20;
  else if (suffix == "G") scale = 0x1p30;
  else if (suffix == "T") scale = 0x1p40;
  else if (!suffix.empty() && suffix != "B") throw bad();
  const double bytes = value * scale;
  if (!(bytes >= 1.0) || !(bytes < 0x1p63)) throw bad();
  return uint64_t(bytes);
}

std::string formatBytes(uint64_t bytes) {
  static const char* kUnits[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  if (bytes < 1024) return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
  double v = double(bytes);
  int unit = -1;
  while (v >= 1024.0 && unit < 5) {
    v /= 1024.0;
    ++unit;
  }
  char text[32];
  std::snprintf(text, sizeof text, "%.1f %s", v, kUnits[unit]);
  return text;
}

uint64_t memoryLimit() {
  const uint64_t set = gLimit.load(std::memory_order_relaxed);
  return set != 0 ? set : defaultMemoryLimit();
}

void setMemoryLimit(uint64_t bytes) { gLimit.store(bytes, std::memory_order_relaxed); }

void MemoryBudget::charge(uint64_t bytes, std::string_view what) {
  const uint64_t total = bytes > UINT64_MAX - used_ ? UINT64_MAX : used_ + bytes;
  if (total > limit_) {
    throw InputError(std::string(what) + " needs " + formatBytes(bytes) +
                     (used_ > 0 ? ", which with the " + formatBytes(used_) + " already taken" : std::string(", which")) +
                     " exceeds the memory limit of " + formatBytes(limit_) + " (--max-memory)");
  }
  used_ = total;
}

}  // namespace pr
