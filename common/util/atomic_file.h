// Output files appear whole or not at all: each is written to a temporary beside its target
// (same folder, so the rename is atomic), renamed over the target once complete, and removed
// if the write fails, throws, or the process is interrupted (interrupt.h).
#pragma once

#include <filesystem>
#include <string_view>

namespace pr {

class TempFile {
 public:
  // ".<name>.tmp<pid>" beside `target`; throws InputError naming `what` when the target's
  // folder does not exist.
  TempFile(const std::filesystem::path& target, std::string_view what);
  ~TempFile();
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;

  const std::filesystem::path& path() const { return temp_; }
  // Renames the temporary over the target; throws InputError naming `what` on failure.
  void commit();

 private:
  std::filesystem::path target_, temp_;
  std::string what_;
  int slot_ = -1;
  bool committed_ = false;
};

// `bytes` to `path` through a TempFile; `what` names the file in messages ("image file").
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes, std::string_view what = "file");

}  // namespace pr
