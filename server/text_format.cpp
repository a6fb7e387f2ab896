#include "server/text_format.h"

#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/io/zero_copy_stream_impl.h>
#include <google/protobuf/text_format.h>

#include <fstream>

namespace leaflux {
namespace {

class FirstError : public google::protobuf::io::ErrorCollector {
  public:
    void AddError(int line, google::protobuf::io::ColumnNumber column,
                  const std::string& message) override {
        if (!error_) error_ = {line + 1, column + 1, message};
    }
    struct Error {
        int line, column;
        std::string message;
    };
    const std::optional<Error>& Get() const { return error_; }

  private:
    std::optional<Error> error_;
};

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
    const auto& error = errors.Get();
    if (!error) return TextFormatError{false, path, "does not parse"};
    return TextFormatError{
        false, path + ":" + std::to_string(error->line) + ":" + std::to_string(error->column),
        error->message};
}

}  // namespace leaflux
