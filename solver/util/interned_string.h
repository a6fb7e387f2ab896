// A string many values hold alike (an organ's optics id: a few distinct ones among the
// hundreds of thousands of organs of a plantation), kept once for all of them: 16 bytes a
// holder where a std::string takes 32, the text shared by every holder of the same. Made
// from any string, read as a const std::string&; immutable. Texts no holder keeps any more
// are dropped from the shared table as it grows, so a long-running daemon's does not.
#pragma once

#include <memory>
#include <ostream>
#include <string>
#include <string_view>

namespace leaflux {

class InternedString {
  public:
    InternedString() = default;              // the empty string
    InternedString(std::string_view text);   // NOLINT(google-explicit-constructor)
    InternedString(const std::string& text)  // NOLINT(google-explicit-constructor)
        : InternedString(std::string_view(text)) {}
    InternedString(const char* text)  // NOLINT(google-explicit-constructor)
        : InternedString(std::string_view(text)) {}

    const std::string& str() const;
    operator const std::string&() const { return str(); }  // NOLINT(google-explicit-constructor)
    bool empty() const { return !text_; }
    // One text, one copy: equal texts are held by the same pointer.
    friend bool operator==(const InternedString& a, const InternedString& b) {
        return a.text_ == b.text_;
    }
    friend std::ostream& operator<<(std::ostream& out, const InternedString& s) {
        return out << s.str();
    }

  private:
    std::shared_ptr<const std::string> text_;  // null: empty
};

}  // namespace leaflux
