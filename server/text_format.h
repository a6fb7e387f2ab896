// Protobuf text-format files (scene files, scenario files), read with errors that say where.
#pragma once

#include <google/protobuf/message.h>

#include <cstddef>
#include <functional>
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

// A text-format file whose top-level fields named `field` (a scene's nodes) are read apart
// from the rest, a run of them at a time, so that a large message never sits whole beside
// what it becomes. Such a field is taken apart when it starts a line (`nodes {`, `nodes:
// {` or `nodes <`) and its closing brace ends one; anything else about it is left in the
// rest, whose parse then holds it (a caller reads such a file whole instead).
class SplitTextFile {
  public:
    SplitTextFile(std::string path, std::string field)
        : path_(std::move(path)), field_(std::move(field)) {}
    // The file without the fields taken apart (their lines left empty, so that every error
    // keeps its line and column) into `rest`, and how many were taken apart.
    std::optional<TextFormatError> ReadRest(google::protobuf::Message& rest, std::size_t& taken);
    // The fields taken apart, in order, runs of them at a time: each run parsed into `run`
    // (what it held before cleared), then onRun().
    std::optional<TextFormatError> ForEachRun(google::protobuf::Message& run,
                                              const std::function<void()>& onRun);

  private:
    // Walks the file: onLines(lines, apart, first, count) for each stretch of whole lines
    // (each ending in a newline; `first` the 0-based number of the first), `apart` when they
    // are a field taken apart, and then onField().
    template <class OnLines, class OnField>
    std::optional<TextFormatError> Walk(const OnLines& onLines, const OnField& onField);

    std::string path_, field_;
};

}  // namespace leaflux
