#include "solver/util/memory.h"

#include <malloc.h>
#include <sys/resource.h>

#include <fstream>
#include <string>

namespace leaflux {

std::int64_t PeakRssBytes() {
    // VmHWM follows ResetPeakRss; getrusage's maximum never goes down.
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);) {
        if (line.rfind("VmHWM:", 0) == 0) return std::stoll(line.substr(6)) * 1024;  // kB
    }
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<std::int64_t>(usage.ru_maxrss) * 1024;  // Linux reports KiB
}

std::int64_t ResidentBytes() {
    malloc_trim(0);
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);) {
        if (line.rfind("VmRSS:", 0) == 0) return std::stoll(line.substr(6)) * 1024;  // kB
    }
    return 0;
}

bool ResetPeakRss() {
    malloc_trim(0);  // what earlier runs freed goes back to the kernel, out of the new peak
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
