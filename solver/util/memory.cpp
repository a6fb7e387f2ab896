#include "solver/util/memory.h"

#include <malloc.h>
#include <sys/resource.h>

#include <algorithm>
#include <fstream>
#include <string>

namespace leaflux {
namespace {

// A size line of /proc/self/status ("VmHWM:", "VmRSS:"), in bytes; -1 where it has none.
std::int64_t StatusBytes(const std::string& key) {
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);) {
        if (line.rfind(key, 0) == 0) return std::stoll(line.substr(key.size())) * 1024;  // kB
    }
    return -1;
}

}  // namespace

std::int64_t PeakRssBytes() {
    // VmHWM follows ResetPeakRss; getrusage's maximum never goes down.
    if (const std::int64_t peak = StatusBytes("VmHWM:"); peak >= 0) return peak;
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<std::int64_t>(usage.ru_maxrss) * 1024;  // Linux reports KiB
}

std::int64_t ResidentBytes() {
    HandFreedPagesBack();
    return std::max<std::int64_t>(StatusBytes("VmRSS:"), 0);
}

void HandFreedPagesBack() { malloc_trim(0); }

std::size_t FreeHeapBytes() { return mallinfo2().fordblks; }

bool ResetPeakRss() {
    HandFreedPagesBack();  // what earlier runs freed, out of the new peak
    std::ofstream clearRefs("/proc/self/clear_refs");
    clearRefs << "5";  // 5: reset the peak resident set size to the current one
    clearRefs.flush();
    return static_cast<bool>(clearRefs);
}

double CpuSeconds() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
           1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

}  // namespace leaflux
