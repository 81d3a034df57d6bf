// Opens one of the program's own shared modules - code kept out of the executable because
// what it links costs every process at start-up (OpenImageIO for images, MPI for running
// across processes) - and returns its entry point.
#pragma once

namespace pr {

// Looks for the module `file` at $`pathVariable` when that is set, else beside the executable,
// in ../lib from it (the build tree: build/tools/parrender and build/lib/) and in the build's
// lib/ directory; opens it (symbols bound lazily, kept local, never closed) and returns the
// address of its `entry` symbol. Throws std::runtime_error naming the module and where it was
// looked for.
void* openModuleEntry(const char* file, const char* pathVariable, const char* entry);

}  // namespace pr
