// The memory a run may take (`--max-memory`): a file or request that would need more is an
// input error raised before the allocation, naming what needs the memory and the limit, so an
// absurd accessor count, image size or frame size is a message rather than an OOM kill.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace pr {

// Physical memory of the machine in bytes (sysconf), 0 when it cannot be read.
uint64_t physicalMemoryBytes();

// The default limit: three quarters of physical memory, leaving room for the OS and other
// processes; 4 GiB when physical memory is unknown.
uint64_t defaultMemoryLimit();

// "512M", "2G", "1.5GiB", "1000000" (bytes) -> bytes; throws InputError (naming `option`
// when not empty) on anything else or on zero.
uint64_t parseByteSize(std::string_view text, std::string_view option = "--max-memory");

// "1.5 GiB", "512 MiB", "900 KiB", "17 bytes" for messages.
std::string formatBytes(uint64_t bytes);

// The process-wide limit, set once by the CLI from --max-memory (default defaultMemoryLimit()).
uint64_t memoryLimit();
void setMemoryLimit(uint64_t bytes);

// Running total of the large allocations one job makes (a load, a frame), against a limit.
class MemoryBudget {
 public:
  explicit MemoryBudget(uint64_t limit = memoryLimit()) : limit_(limit) {}

  // Counts `bytes` for `what`; throws InputError ("<what> needs 3.0 GiB, which with the
  // 1.2 GiB already taken exceeds the memory limit of 4.0 GiB (--max-memory)") when the
  // total would exceed the limit. Saturates instead of overflowing.
  void charge(uint64_t bytes, std::string_view what);

  uint64_t used() const { return used_; }
  uint64_t limit() const { return limit_; }

 private:
  uint64_t limit_;
  uint64_t used_ = 0;
};

// a * b, saturating at UINT64_MAX: sizes computed from file counts never wrap around.
inline uint64_t saturatingMul(uint64_t a, uint64_t b) {
  return a != 0 && b > UINT64_MAX / a ? UINT64_MAX : a * b;
}

}  // namespace pr
