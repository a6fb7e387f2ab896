#include "solver/instancing/phase_key.h"

#include <cstdio>

#include "solver/util/content_hash.h"

namespace leaflux {
namespace {

// Percent-escapes the characters Canonical() uses as separators, '%' itself and controls.
std::string Escaped(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        const auto byte = static_cast<unsigned char>(c);
        if (c == '|' || c == '=' || c == ',' || c == '%' || byte < 0x20 || byte == 0x7f) {
            char code[4];
            std::snprintf(code, sizeof code, "%%%02X", byte);
            out += code;
        } else {
            out += c;
        }
    }
    return out;
}

}  // namespace

std::string JoinBands(const std::vector<std::string>& bands) {
    std::string out;
    for (std::size_t b = 0; b < bands.size(); ++b) out += (b ? "," : "") + Escaped(bands[b]);
    return out;
}

std::string PhaseKey::Canonical() const {
    return "code=" + std::to_string(codeVersion) + "|species=" + Escaped(species) +
           "|policy=" + Escaped(policyHash) + "|signature=" + Escaped(signature) +
           "|optics=" + Escaped(opticsHash) + "|bands=" + std::to_string(bands.size()) + ":" +
           JoinBands(bands) + "|kind=" + PhaseKindName(kind) +
           "|level=" + std::to_string(directionLevel) + "|settings=" + Escaped(settings);
}

std::string PhaseKey::HashHex() const { return ContentHash().Add(Canonical()).Hex(); }

}  // namespace leaflux
