#include "solver/util/error.h"

namespace leaflux {
namespace {
std::string Describe(ErrorCode code, const std::string& field, const std::string& message,
                     std::optional<std::uint64_t> node) {
    std::string text = ErrorCodeName(code);
    if (node) text += " [node " + std::to_string(*node) + "]";
    if (!field.empty()) text += " " + field;
    return text + ": " + message;
}
}  // namespace

const char* ErrorCodeName(ErrorCode code) {
    switch (code) {
        case ErrorCode::kInvalidArgument:
            return "invalid_argument";
        case ErrorCode::kNotFound:
            return "not_found";
        case ErrorCode::kAlreadyExists:
            return "already_exists";
        case ErrorCode::kDegenerate:
            return "degenerate";
        case ErrorCode::kCycle:
            return "cycle";
        case ErrorCode::kParse:
            return "parse";
        case ErrorCode::kIo:
            return "io";
        case ErrorCode::kUnsupported:
            return "unsupported";
    }
    return "unknown";
}

InputError::InputError(ErrorCode code, std::string field, const std::string& message,
                       std::optional<std::uint64_t> node)
    : std::runtime_error(Describe(code, field, message, node)),
      code_(code),
      field_(std::move(field)),
      message_(message),
      node_(node) {}

}  // namespace leaflux
