// `leaflux phase-db stats|list|verify|compact|export`: the phase-function database's file
// as users inspect it. Every command but compact opens it read-only.
#pragma once

#include <cstdint>
#include <string>

namespace CLI {
class App;
}

namespace leaflux {

class PhaseDbCli {
  public:
    // Adds `phase-db` and its subcommands to `parent`.
    explicit PhaseDbCli(CLI::App& parent);
    bool Parsed() const;
    // Runs the parsed subcommand: 0 when done (verify: when the file is sound), 1 when
    // verify found damage. Throws InputError naming the file or the row.
    int Run() const;

  private:
    CLI::App* app_;
    CLI::App *stats_, *list_, *verify_, *compact_, *export_;
    std::string path_;
    bool keysOnly_ = false;
    std::string key_;
    std::int64_t id_ = 0;
    std::string out_ = "-";
};

}  // namespace leaflux
