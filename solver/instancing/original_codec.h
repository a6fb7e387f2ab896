// An Original as bytes, for the phase-function database: a compact little-endian blob that
// keeps every float as it was computed, so that a function read back is bit-identical.
//
// Layout (format version 1): "LFOR", a version byte, the box (6 doubles), τ (level,
// channels, count, floats), f (kind byte, level, bands, count, floats), then the provenance
// (strings as a u32 length and bytes, numbers as they are held).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "solver/instancing/original.h"

namespace leaflux {

inline constexpr std::uint8_t kOriginalFormatVersion = 2;  // 2: with the absorption

std::vector<std::uint8_t> EncodeOriginal(const Original& original);
// Throws InputError(kParse, `what`) when the bytes are not an original of a known format
// version: truncated, trailing bytes, counts that do not fit their kind and level.
Original DecodeOriginal(std::span<const std::uint8_t> blob, const std::string& what);

// What an original holds in memory (bytes): its values, its strings and itself.
std::size_t OriginalBytes(const Original& original);

}  // namespace leaflux
