// Process resource readings for solve statistics and benchmarks.
#pragma once

#include <cstdint>

namespace leaflux {

// Peak resident set size of the process so far (bytes), from the kernel.
std::int64_t PeakRssBytes();
// CPU time used by the process so far, all threads (seconds).
double CpuSeconds();

}  // namespace leaflux
