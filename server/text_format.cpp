#include "server/text_format.h"

#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/io/zero_copy_stream_impl.h>
#include <google/protobuf/text_format.h>

#include <cctype>
#include <fstream>

namespace leaflux {
namespace {

class FirstError : public google::protobuf::io::ErrorCollector {
  public:
    // `firstLine`: the line of the file (0-based) the parsed text starts on.
    explicit FirstError(int firstLine = 0) : firstLine_(firstLine) {}
    void AddError(int line, google::protobuf::io::ColumnNumber column,
                  const std::string& message) override {
        if (!error_) error_ = {firstLine_ + line + 1, column + 1, message};
    }
    struct Error {
        int line, column;
        std::string message;
    };
    const std::optional<Error>& Get() const { return error_; }

  private:
    int firstLine_;
    std::optional<Error> error_;
};

std::optional<TextFormatError> Located(const std::string& path, const FirstError& errors) {
    const auto& error = errors.Get();
    if (!error) return TextFormatError{false, path, "does not parse"};
    return TextFormatError{
        false, path + ":" + std::to_string(error->line) + ":" + std::to_string(error->column),
        error->message};
}

// Parses `text`, which starts on line `firstLine` (0-based) of the file `path`, into message
// (as a whole file is: a field that is not repeated may be given once).
std::optional<TextFormatError> ParseLines(const std::string& path, const std::string& text,
                                          int firstLine, google::protobuf::Message& message) {
    google::protobuf::TextFormat::Parser parser;
    FirstError errors(firstLine);
    parser.RecordErrorsTo(&errors);
    if (parser.ParseFromString(text, &message)) return std::nullopt;
    return Located(path, errors);
}

// Whether `line` starts a field `name` whose value is a message: `name {`, `name: {` or
// `name <`, after any indentation.
bool StartsField(const std::string& line, const std::string& name) {
    std::size_t i = line.find_first_not_of(" \t");
    if (i == std::string::npos || line.compare(i, name.size(), name) != 0) return false;
    i += name.size();
    if (i < line.size() && (std::isalnum(static_cast<unsigned char>(line[i])) || line[i] == '_'))
        return false;  // a longer name
    i = line.find_first_not_of(" \t", i);
    if (i != std::string::npos && line[i] == ':') i = line.find_first_not_of(" \t", i + 1);
    return i != std::string::npos && (line[i] == '{' || line[i] == '<');
}

// A line's nesting, outside strings and comments: the depth after it, from `depth` before;
// `touched`: it came down to 0 in the line; `closed`: so, with nothing after but blanks or
// a comment.
struct Nesting {
    int depth = 0;
    bool touched = false, closed = false;
};
Nesting Nest(const std::string& line, int depth) {
    Nesting out;
    char quote = 0;
    std::size_t closedAt = std::string::npos;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quote) {
            if (c == '\\')
                ++i;
            else if (c == quote)
                quote = 0;
        } else if (c == '"' || c == '\'') {
            quote = c;
        } else if (c == '#') {
            break;
        } else if (c == '{' || c == '<' || c == '[') {
            ++depth;
        } else if (c == '}' || c == '>' || c == ']') {
            if (--depth == 0 && closedAt == std::string::npos) closedAt = i;
        } else if (closedAt != std::string::npos && !std::isspace(static_cast<unsigned char>(c))) {
            closedAt = line.size();  // more after the close
        }
    }
    out.depth = depth;
    out.touched = closedAt != std::string::npos;
    out.closed = depth == 0 && closedAt < line.size();
    return out;
}

}  // namespace

std::optional<TextFormatError> ReadTextFormat(const std::string& path,
                                              google::protobuf::Message& message) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return TextFormatError{true, path, "cannot open the file"};
    // Read as it is parsed, never whole: a 240 MB scene file held as text (twice, with a
    // copy of it) took 480 MB of the reading's peak.
    google::protobuf::io::IstreamInputStream stream(&in);
    google::protobuf::TextFormat::Parser parser;
    FirstError errors;
    parser.RecordErrorsTo(&errors);
    if (parser.Parse(&stream, &message)) return std::nullopt;
    return Located(path, errors);
}

template <class OnLines, class OnField>
std::optional<TextFormatError> SplitTextFile::Walk(const OnLines& onLines, const OnField& onField) {
    std::ifstream in(path_, std::ios::binary);
    if (!in) return TextFormatError{true, path_, "cannot open the file"};
    int depth = 0, number = 0, blockFirst = 0, blockLines = 0;
    std::string block;  // a field that may be taken apart, until it closes
    const auto giveBack = [&](bool apart) {
        if (blockLines == 0) return;
        onLines(block, apart, blockFirst, blockLines);
        if (apart) onField();
        block.clear();
        blockLines = 0;
    };
    for (std::string line; std::getline(in, line); ++number) {
        if (blockLines == 0 && !(depth == 0 && StartsField(line, field_))) {
            depth = Nest(line, depth).depth;
            line += '\n';
            onLines(line, false, number, 1);
            continue;
        }
        const Nesting nesting = Nest(line, blockLines == 0 ? 0 : depth);
        if (blockLines++ == 0) blockFirst = number;
        block += line;
        block += '\n';
        depth = nesting.depth;
        // A field that ends in the middle of a line, or not where it began, stays in the rest.
        if (nesting.touched || depth <= 0) giveBack(nesting.closed);
    }
    giveBack(false);  // not closed: the rest's parse says where
    if (in.bad()) return TextFormatError{true, path_, "cannot read the file"};
    return std::nullopt;
}

std::optional<TextFormatError> SplitTextFile::ReadRest(google::protobuf::Message& rest,
                                                       std::size_t& taken) {
    std::string text;
    taken = 0;
    const auto walked = Walk(
        [&](const std::string& lines, bool apart, int, int count) {
            if (apart) {
                text.append(static_cast<std::size_t>(count), '\n');
            } else {
                text += lines;
            }
        },
        [&] { ++taken; });
    if (walked) return walked;
    return ParseLines(path_, text, 0, rest);
}

std::optional<TextFormatError> SplitTextFile::ForEachRun(google::protobuf::Message& run,
                                                         const std::function<void()>& onRun) {
    // Runs of about a megabyte: the lines from a field taken apart to the end of the last one
    // (what lies between them is whole fields of the rest, parsed again and left unused).
    constexpr std::size_t kRunBytes = 1 << 20;
    std::string text;
    std::size_t complete = 0;  // the text's length at the end of its last field
    int first = 0;
    std::optional<TextFormatError> error;
    const auto flush = [&] {
        if (complete == 0 || error) return;
        text.resize(complete);
        error = ParseLines(path_, text, first, run);
        if (!error) onRun();
        text.clear();
        complete = 0;
    };
    const auto walked = Walk(
        [&](const std::string& lines, bool apart, int number, int) {
            if (text.empty() && !apart) return;
            if (text.empty()) first = number;
            text += lines;
        },
        [&] {
            complete = text.size();
            if (complete >= kRunBytes) flush();
        });
    if (walked) return walked;
    flush();
    return error;
}

}  // namespace leaflux
