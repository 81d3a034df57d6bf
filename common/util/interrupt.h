// Ctrl-C (SIGINT) and SIGTERM stop parrender at once: there is nothing worth finishing in a
// half-done render, and every output is written to a temporary name and renamed into place
// (atomic_file.h), so the handler only removes the temporaries in flight and exits with
// 128 + the signal (130 for SIGINT, 143 for SIGTERM). A signal the process inherited as
// ignored (nohup, a non-interactive shell's background job) stays ignored.
// No output file is ever left half written, and an earlier good one is never replaced.
#pragma once

namespace pr {

// Installs the handler for SIGINT and SIGTERM (the program calls it once, first thing).
void installInterruptHandler();

// The temporaries the handler removes: at most kMaxTemporaries at once, paths up to 4095
// bytes; registerTemporary returns a slot (or -1 when none is free or the path is too long:
// the file is then only removed by its owner). registerTemporaryFolder: a folder being filled
// (a report's), removed with everything in it, down to kMaxFolderDepth levels below it.
inline constexpr int kMaxTemporaries = 16;
inline constexpr int kMaxFolderDepth = 8;
int registerTemporary(const char* path);
int registerTemporaryFolder(const char* path);
void unregisterTemporary(int slot);

}  // namespace pr
