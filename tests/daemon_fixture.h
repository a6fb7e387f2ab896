// leafluxd in the test process, serving on a loopback port of its own choosing, with a
// raw client connection to it.
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <thread>

#include "server/daemon.h"
#include "server/executor.h"
#include "server/transport.h"

namespace leaflux {

class DaemonOnLoopback : public ::testing::Test {
  protected:
    void SetUp() override {
        TransportLimits limits;
        limits.maxBytes = 1 << 20;  // small, so that an oversized message is cheap to send
        server_ = std::make_unique<RouterServer>(context_, "tcp://127.0.0.1:*", limits);
        thread_ = std::thread([this] {
            server_->Serve(
                DaemonDispatch(daemon_, executor_),
                [](const OversizedMessage& m) {
                    return TooLargeReply(m.bytes, m.frames, m.head, 1 << 20);
                },
                [this] { return daemon_.ShutdownRequested(); }, stop_);
        });
        client_ = std::make_unique<ClientConnection>(context_, server_->Endpoint());
    }
    void TearDown() override {
        stop_ = true;
        thread_.join();
    }

    // Sends `request`, of the current protocol version unless it says another.
    v1::Reply Call(v1::Request request) {
        if (request.version() == v1::PROTOCOL_VERSION_UNSPECIFIED)
            request.set_version(v1::PROTOCOL_VERSION_CURRENT);
        std::string bytes, reply;
        request.SerializeToString(&bytes);
        EXPECT_TRUE(client_->Call(bytes, reply, 60000));
        v1::Reply decoded;
        EXPECT_TRUE(decoded.ParseFromString(reply));
        return decoded;
    }

    zmq::context_t context_;
    Daemon daemon_;
    KeyedExecutor executor_{2};
    std::unique_ptr<RouterServer> server_;
    std::unique_ptr<ClientConnection> client_;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

}  // namespace leaflux
