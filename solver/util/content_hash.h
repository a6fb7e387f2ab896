// A content hash for keys and checksums: 64-bit FNV-1a over bytes, written as 16 hex digits.
// Not cryptographic: it tells apart contents (a policy, a set of optics, a stored row), it
// does not resist an adversary.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>

namespace leaflux {

class ContentHash {
  public:
    ContentHash& Add(const void* data, std::size_t bytes) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < bytes; ++i) {
            state_ ^= p[i];
            state_ *= 0x100000001b3ull;
        }
        return *this;
    }
    ContentHash& Add(std::string_view text) {
        Add(text.data(), text.size());
        return Add(static_cast<std::uint64_t>(text.size()));  // "ab","c" differs from "a","bc"
    }
    template <class T>
    ContentHash& Add(const T& value) requires std::is_arithmetic_v<T> {
        return Add(&value, sizeof value);
    }
    template <class T>
    ContentHash& Add(std::span<const T> values) {
        return Add(values.data(), values.size_bytes());
    }
    std::uint64_t Value() const { return state_; }
    std::string Hex() const {
        char text[17];
        std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(state_));
        return text;
    }

  private:
    std::uint64_t state_ = 0xcbf29ce484222325ull;
};

}  // namespace leaflux
