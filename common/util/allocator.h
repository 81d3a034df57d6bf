// Process-wide allocator settings for the programs (parrender, the benchmarks), called first
// thing in main. Libraries never call it; tests run with the allocator's defaults.
#pragma once

namespace pr {

// Keeps memory that was freed in the process for its next allocations instead of handing it
// back to the operating system. By default glibc maps every block of 128 KiB and more on its
// own and unmaps it when freed (raising that threshold only after such a free), and trims the
// top of each thread's arena back to the OS: a buffer freed and allocated again every frame or
// every message batch (a batch of screen triangles, a batch of rays) is then faulted in and
// zero-filled page by page each time. On the 2-core development machine, whose page faults
// are expensive, that was 1.3 of sort-middle's 1.6 ms geometry stage on the Cornell box.
// Sets the mmap threshold to 256 MiB and the trim threshold to 1 GiB (glibc mallopt; a no-op
// elsewhere).
void retainFreedMemory();

}  // namespace pr
