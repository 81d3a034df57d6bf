#include "common/util/atomic_file.h"

#include <unistd.h>

#include <fstream>
#include <string>

#include "common/util/error.h"
#include "common/util/interrupt.h"

namespace pr {

namespace fs = std::filesystem;

TempFile::TempFile(const fs::path& target, std::string_view what) : target_(target), what_(what) {
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError("cannot write " + what_ + " '" + target.string() + "': directory '" + dir.string() + "' does not exist");
  // Built by appending: GCC 12 warns falsely (-Wrestrict) on "." + string.
  std::string name = ".";
  name += target.filename().string();
  name += ".tmp";
  name += std::to_string(::getpid());
  temp_ = dir / name;
  slot_ = registerTemporary(temp_.c_str());
}

TempFile::~TempFile() {
  if (!committed_) {
    std::error_code ignored;
    fs::remove(temp_, ignored);
  }
  unregisterTemporary(slot_);
}

void TempFile::commit() {
  std::error_code ec;
  fs::rename(temp_, target_, ec);
  if (ec) throw InputError("cannot write " + what_ + " '" + target_.string() + "': " + ec.message());
  committed_ = true;
}

void writeFileAtomically(const fs::path& path, std::string_view bytes, std::string_view what) {
  TempFile temp(path, what);
  {
    std::ofstream file(temp.path(), std::ios::binary | std::ios::trunc);
    if (file) file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!file || !file.flush()) throw InputError("cannot write " + std::string(what) + " '" + path.string() + "'");
  }
  temp.commit();
}

}  // namespace pr
