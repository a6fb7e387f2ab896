// A small C++ client of leafluxd: typed calls over one connection. Used by the growth model
// (growth_stub), the command line and the tests; it links the protocol and ZeroMQ only.
//
// Every request gets a new request id and only the reply of that id is taken: a late reply
// to a request given up on, or a message that is not a Reply, is dropped. A request unanswered
// within its timeout is an ERROR_CODE_IO ClientError naming the endpoint, and the connection is
// made anew. Before sending a request of over 1 MiB the client learns the daemon's message limit
// (Status, once a connection) and refuses a request over it with ERROR_CODE_TOO_LARGE: ZeroMQ would
// cut off one over twice the limit unanswered.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
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

// How long a client waits for a reply. Status, CloseSession and Shutdown wait `statusMs`;
// OpenSession, Resync, Cycle and Render, which validate, solve or draw a scene, wait `sceneMs` plus
// `perOrganMs` for each organ the session's scene holds (as far as the client sent them).
struct ClientTimeouts {
    int statusMs = 30'000;
    int sceneMs = 60'000;
    int perOrganMs = 10;

    // Every request waits `ms`.
    static ClientTimeouts All(int ms) { return {ms, ms, 0}; }
};

class Client {
  public:
    // `curveServerKey`: the daemon's public key when it speaks CurveZMQ ("" otherwise).
    explicit Client(const std::string& endpoint, const std::string& curveServerKey = "",
                    ClientTimeouts timeouts = {});
    Client(const std::string& endpoint, const std::string& curveServerKey, int timeoutMs)
        : Client(endpoint, curveServerKey, ClientTimeouts::All(timeoutMs)) {}

    // Sends one request (the version and a request id are filled in) and returns the reply
    // as it came, errors included. Throws ClientError when no valid reply arrives in time.
    v1::Reply Call(v1::Request request);

    // The typed calls: each throws ClientError when the daemon answers with an Error.
    std::string Open(const v1::OpenSession& open);  // the session id
    v1::CycleResult Cycle(const v1::Cycle& cycle);
    // A cycle that is not answered in time, or whose session the daemon does not know (it
    // restarted), is sent once more after a new connection and `resync()`: the session's
    // whole scene as it was before this cycle. A second failure throws.
    v1::CycleResult Cycle(const v1::Cycle& cycle, const std::function<v1::Resync()>& resync);
    v1::StatusReply Status(const std::string& session = "");
    void Resync(const v1::Resync& resync);
    void Close(const std::string& session);
    // A picture of the session's light as its last cycle returned it.
    v1::Picture Render(const v1::RenderRequest& render);
    void Shutdown();

    // A new connection to the same endpoint: replies to the old one are never read.
    void Reconnect();
    const std::string& Endpoint() const { return endpoint_; }

  private:
    v1::Reply Expect(v1::Request request, v1::Reply::BodyCase expected);
    int TimeoutMs(const v1::Request& request) const;

    std::string endpoint_, curveServerKey_;
    ClientTimeouts timeouts_;
    zmq::context_t context_;
    std::unique_ptr<ClientConnection> connection_;
    std::uint64_t nextRequest_ = 1;
    std::map<std::string, std::int64_t> organs_;   // by session: organs sent, removals aside
    std::optional<std::int64_t> maxMessageBytes_;  // the daemon's, once asked (0: not told)
};

}  // namespace leaflux
