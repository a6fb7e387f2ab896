// A small C++ client of leafluxd: typed calls over one connection. Used by the growth model
// (growth_stub), the command line and the tests; it links the protocol and ZeroMQ only.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

#include "leaflux.pb.h"
#include "server/transport.h"

namespace leaflux {

// The daemon answered with an Error (kept whole: code, field, node), or did not answer.
class ClientError : public std::runtime_error {
  public:
    explicit ClientError(v1::Error error);
    const v1::Error& Error() const { return error_; }

  private:
    v1::Error error_;
};

class Client {
  public:
    // `curveServerKey`: the daemon's public key when it speaks CurveZMQ ("" otherwise).
    explicit Client(const std::string& endpoint, const std::string& curveServerKey = "",
                    int timeoutMs = 600000);

    // Sends one request (the version and a request id are filled in) and returns the reply
    // as it came, errors included. Throws ClientError when no valid reply arrives in time.
    v1::Reply Call(v1::Request request);

    // The typed calls: each throws ClientError when the daemon answers with an Error.
    std::string Open(const v1::OpenSession& open);  // the session id
    v1::CycleResult Cycle(const v1::Cycle& cycle);
    v1::StatusReply Status(const std::string& session = "");
    void Resync(const v1::Resync& resync);
    void Close(const std::string& session);
    void Shutdown();

  private:
    v1::Reply Expect(v1::Request request, v1::Reply::BodyCase expected);

    zmq::context_t context_;
    ClientConnection connection_;
    int timeoutMs_;
    std::uint64_t nextRequest_ = 1;
};

}  // namespace leaflux
