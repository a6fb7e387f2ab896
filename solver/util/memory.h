// Process resource readings for solve statistics and benchmarks.
#pragma once

#include <cstddef>
#include <cstdint>

namespace leaflux {

// Peak resident set size of the process (bytes) since it started or since the last
// successful ResetPeakRss, from the kernel.
std::int64_t PeakRssBytes();
// Resident set size of the process now (bytes), after HandFreedPagesBack, from the kernel.
std::int64_t ResidentBytes();
// Hands the whole pages of freed memory back to the kernel (malloc_trim). malloc keeps
// them otherwise, and memory a solve's setup freed stays in its resident size to the end.
void HandFreedPagesBack();
// The bytes malloc holds free in its main heap (mallinfo2): what a step freed is the rise.
std::size_t FreeHeapBytes();
// Starts a new peak at the current resident size, so that one process can measure the
// peak of several runs in turn (Linux /proc/self/clear_refs). False when the kernel does
// not allow it: the peak then stays the process's.
bool ResetPeakRss();
// CPU time used by the process so far, all threads (seconds).
double CpuSeconds();

}  // namespace leaflux
