// leafluxd as a process of its own, as users run it: started on a loopback port it picks
// (tcp://127.0.0.1:*), found in its log, stopped by a signal. The binary is the build's
// unless $LEAFLUXD names another (to run a test against an older build).
#pragma once

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "leaflux.pb.h"
#include "server/transport.h"

extern char** environ;

namespace leaflux::test {

class DaemonProcess {
  public:
    // Starts leafluxd with `arguments` (besides --bind, unless they name one) and waits
    // until its log names the endpoint it serves.
    explicit DaemonProcess(std::vector<std::string> arguments = {}) {
        const char* binary = std::getenv("LEAFLUXD");
        binary_ = binary ? binary : LEAFLUX_LEAFLUXD;
        static int serial = 0;
        log_ =
            (std::filesystem::temp_directory_path() / ("leafluxd-test-" + std::to_string(getpid()) +
                                                       "-" + std::to_string(serial++) + ".log"))
                .string();
        bool bind = false;
        for (const std::string& a : arguments) bind = bind || a == "--bind";
        if (!bind) arguments.insert(arguments.begin(), {"--bind", "tcp://127.0.0.1:*"});
        Start(arguments);
    }
    ~DaemonProcess() {
        if (pid_ > 0) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, nullptr, 0);
        }
        std::filesystem::remove(log_);
    }
    DaemonProcess(const DaemonProcess&) = delete;
    DaemonProcess& operator=(const DaemonProcess&) = delete;

    const std::string& Endpoint() const { return endpoint_; }
    pid_t Pid() const { return pid_; }
    std::string Log() const {
        std::ifstream in(log_);
        std::stringstream text;
        text << in.rdbuf();
        return text.str();
    }

    void Signal(int signal) const { ::kill(pid_, signal); }

    // The exit status within `timeout`, or nullopt while it still runs.
    std::optional<int> Wait(std::chrono::milliseconds timeout) {
        const auto end = std::chrono::steady_clock::now() + timeout;
        for (;;) {
            int status = 0;
            const pid_t done = ::waitpid(pid_, &status, WNOHANG);
            if (done == pid_) {
                pid_ = -1;
                return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
            }
            if (std::chrono::steady_clock::now() > end) return std::nullopt;
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
    }

    // Resident memory of the daemon (kB), from /proc.
    long RssKb() const {
        std::ifstream in("/proc/" + std::to_string(pid_) + "/status");
        for (std::string line; std::getline(in, line);) {
            if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
        }
        return -1;
    }

  private:
    void Start(const std::vector<std::string>& arguments) {
        std::vector<std::string> all = {binary_, "--log-file", log_};
        all.insert(all.end(), arguments.begin(), arguments.end());
        std::vector<char*> argv;
        for (std::string& a : all) argv.push_back(a.data());
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
        posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
        const int failed =
            posix_spawn(&pid_, binary_.c_str(), &actions, nullptr, argv.data(), environ);
        posix_spawn_file_actions_destroy(&actions);
        if (failed) {
            pid_ = -1;
            ADD_FAILURE() << "cannot start " << binary_;
            return;
        }
        const std::regex serving("serving (tcp://[^ ]+)");
        for (int i = 0; i < 500; ++i) {  // 10 s
            std::smatch match;
            const std::string log = Log();
            if (std::regex_search(log, match, serving)) {
                endpoint_ = match[1];
                return;
            }
            if (Wait(std::chrono::milliseconds(20))) break;
        }
        ADD_FAILURE() << binary_ << " did not start serving:\n" << Log();
    }

    std::string binary_, log_, endpoint_;
    pid_t pid_ = -1;
};

// Requests to a daemon as they go on the wire, one at a time; an unanswered one is an
// Error reply with code UNSPECIFIED, and the connection is then made anew.
class WireClient {
  public:
    explicit WireClient(std::string endpoint) : endpoint_(std::move(endpoint)) { Reconnect(); }

    v1::Reply Call(const v1::Request& request, int timeoutMs = 20000) {
        std::string answer;
        v1::Reply reply;
        if (!connection_->Call(request.SerializeAsString(), answer, timeoutMs)) {
            Reconnect();
            reply.mutable_error()->set_message("no reply within " + std::to_string(timeoutMs) +
                                               " ms");
        } else if (!reply.ParseFromString(answer)) {
            reply.mutable_error()->set_message("the reply is not a leaflux.v1.Reply");
        }
        return reply;
    }
    void Reconnect() { connection_ = std::make_unique<ClientConnection>(context_, endpoint_); }

  private:
    std::string endpoint_;
    zmq::context_t context_;
    std::unique_ptr<ClientConnection> connection_;
};

}  // namespace leaflux::test
