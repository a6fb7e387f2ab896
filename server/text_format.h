// Protobuf text-format files (scene files, scenario files), read with errors that say where.
#pragma once

#include <google/protobuf/message.h>

#include <optional>
#include <string>

namespace leaflux {

struct TextFormatError {
    bool unreadable = false;  // the file could not be opened (else: it does not parse)
    std::string where;        // "path:line:column", or the path when unreadable
    std::string what;
};

// Reads `path` into `message`; the first error when it cannot.
std::optional<TextFormatError> ReadTextFormat(const std::string& path,
                                              google::protobuf::Message& message);

}  // namespace leaflux
