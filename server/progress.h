// The command line's progress bar: "  <label>  40 %" on stderr, rewritten in place at each
// tenth, ended by a newline at 100 %. The solvers and the generator call it with the
// fraction done (ReferenceOptions::progress, PlantationParameters::progress).
#pragma once

#include <cstdio>
#include <functional>
#include <string>

namespace leaflux {

inline std::function<void(double)> ProgressBar(std::string label) {
    return [label = std::move(label), last = -1](double done) mutable {
        const int tenth = static_cast<int>(done * 10.0);
        if (tenth <= last) return;
        last = tenth;
        std::fprintf(stderr, "\r  %s %3d %%", label.c_str(), 10 * tenth);
        if (tenth >= 10) std::fprintf(stderr, "\n");
        std::fflush(stderr);
    };
}

}  // namespace leaflux
