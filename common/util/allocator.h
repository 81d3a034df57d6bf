// Allocator settings: process-wide ones for the programs (parrender, the benchmarks), called
// first thing in main (libraries never call retainFreedMemory; tests run with the allocator's
// defaults), and the large-page hint for the big arrays the libraries fill at once.
#pragma once

#include <cstddef>
#include <vector>

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

// Asks the kernel to back the whole 2 MiB pages inside [data, data + bytes) with 2 MiB pages
// (Linux transparent huge pages, madvise MADV_HUGEPAGE; a no-op elsewhere or when the system
// has them switched off). Worth it for memory about to be written for the first time in one go:
// each 4 KiB page is a page fault on first touch, and the BVH build of the 1M-triangle
// landscape, which fills about 150 MB of such memory, took 0.6-0.7 s with 2 MiB pages against
// 1.0-1.3 s without on the 2-core development machine.
void adviseHugePages(const void* data, std::size_t bytes);

// Reserves room for n elements in v and gives it the hint above (before anything is written).
template <class T>
void reserveHugePages(std::vector<T>& v, std::size_t n) {
  v.reserve(n);
  adviseHugePages(v.data(), v.capacity() * sizeof(T));
}

}  // namespace pr
