// Errors in input from outside leaflux (files, requests, command lines). Each names what
// it concerns: a field path such as "optics[leaf].bands[NIR].rho_upper", a node id, or a
// file location, so that a user can find and mend the offending input.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace leaflux {

enum class ErrorCode {
    kInvalidArgument,  // a value out of its domain (NaN, negative reflectance, ρ+τ > 1, …)
    kNotFound,         // a reference to something that does not exist (parent, optics, band)
    kAlreadyExists,    // a duplicate id or name
    kDegenerate,       // geometry that cannot be lit: zero-area or collapsed triangles
    kCycle,            // a topology whose parent links loop
    kParse,            // a file or message that cannot be read
    kIo,               // a file that cannot be opened
    kUnsupported,      // valid input leaflux does not handle (yet)
};

const char* ErrorCodeName(ErrorCode code);

class InputError : public std::runtime_error {
  public:
    InputError(ErrorCode code, std::string field, const std::string& message,
               std::optional<std::uint64_t> node = std::nullopt);

    ErrorCode Code() const { return code_; }
    // The field path the error concerns ("" when it concerns the whole input).
    const std::string& Field() const { return field_; }
    // The botanical node the error concerns, when there is one.
    std::optional<std::uint64_t> Node() const { return node_; }
    // What is wrong, without the code, field and node that what() puts before it: what an
    // error rethrown under another field keeps.
    const std::string& Message() const { return message_; }

  private:
    ErrorCode code_;
    std::string field_;
    std::string message_;
    std::optional<std::uint64_t> node_;
};

}  // namespace leaflux
