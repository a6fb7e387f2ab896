// leaflux's folders under the user's XDG base directories (XDG Base Directory spec): the
// variable's folder when set, else its default under $HOME, else `fallback` (relative to
// the working directory, for an environment with neither).
#pragma once

#include <cstdlib>
#include <string>

namespace leaflux {

// LeafluxDirectory("XDG_DATA_HOME", ".local/share", ".leaflux") → "$XDG_DATA_HOME/leaflux",
// "$HOME/.local/share/leaflux" or ".leaflux".
inline std::string LeafluxDirectory(const char* variable, const char* underHome,
                                    const char* fallback) {
    if (const char* base = std::getenv(variable); base && *base)
        return std::string(base) + "/leaflux";
    if (const char* home = std::getenv("HOME"); home && *home)
        return std::string(home) + "/" + underHome + "/leaflux";
    return fallback;
}

}  // namespace leaflux
