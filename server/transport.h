// ZeroMQ transport of leafluxd: a ROUTER socket that reads whole multipart messages (with
// a cap on frames and bytes), hands the last frame to a handler and sends the reply back
// with the same envelope. It knows nothing of protobuf or of the solver.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <zmq.hpp>
#include <zmq_addon.hpp>

namespace leaflux {

struct TransportLimits {
    std::size_t maxFrames = 8;          // routing frames + delimiter + payload
    std::size_t maxBytes = 256u << 20;  // a message larger than this is refused
};

// CurveZMQ keys, Z85 text (40 characters). A server with a secret key encrypts every
// connection and proves who it is; clients need its public key to talk to it.
struct CurveKeyPair {
    std::string publicKey, secretKey;
    static CurveKeyPair Generate();
};

// The key a file written by `leaflux keygen` holds (40 Z85 characters); nullopt when the
// file cannot be read or holds no such key.
std::optional<std::string> ReadCurveKey(const std::string& path);

// Whether an endpoint stays on this machine: tcp:// on 127.0.0.0/8, localhost or [::1],
// ipc:// and inproc://.
bool IsLoopback(const std::string& endpoint);
// Why `endpoint` cannot be bound or connected to as written ("" when it can): a missing
// transport ("127.0.0.1:5555" for tcp://127.0.0.1:5555), an unknown one.
std::string EndpointProblem(const std::string& endpoint);

// A message refused for its size: what the transport saw of it.
struct OversizedMessage {
    std::size_t bytes = 0, frames = 0;
    std::string head;  // the first bytes of its last frame (the payload), at most 64
};

class RouterServer {
  public:
    // Binds `endpoint` (e.g. tcp://127.0.0.1:5555, tcp://127.0.0.1:* for any port); throws
    // std::runtime_error naming the endpoint when it cannot.
    RouterServer(zmq::context_t& context, const std::string& endpoint, TransportLimits limits = {},
                 const std::string& curveSecretKey = "");
    ~RouterServer();

    // The endpoint actually bound (with the port chosen for a "*").
    std::string Endpoint() const;

    // Called once per message, from any thread, with its reply.
    using Respond = std::function<void(std::string reply)>;
    using Dispatch = std::function<void(std::string payload, Respond respond)>;
    using TooLarge = std::function<std::string(const OversizedMessage& message)>;

    // Serves until `stop` says so (asked at least every 100 ms) or, after a reply has been
    // sent, `stopAfterReply` says so. `dispatch` may answer later from another thread; the
    // socket itself is only ever used by the thread that serves. `tooLarge` makes the
    // reply to a message over the limits. May be called again: replies made in between
    // are sent then.
    void Serve(const Dispatch& dispatch, const TooLarge& tooLarge,
               const std::function<bool()>& stopAfterReply, const std::function<bool()>& stop);
    void Serve(const Dispatch& dispatch, const TooLarge& tooLarge,
               const std::function<bool()>& stopAfterReply, const std::atomic<bool>& stop) {
        Serve(dispatch, tooLarge, stopAfterReply, [&stop] { return stop.load(); });
    }

    // Sends the replies made since the last Serve, then closes the socket, giving ZeroMQ
    // up to `linger` to deliver them; replies made afterwards are dropped.
    void Close(std::chrono::milliseconds linger);

    // A Dispatch that answers at once with `handle`.
    static Dispatch Synchronous(std::function<std::string(const std::string&)> handle);

  private:
    struct Outbox;
    void SendReady();

    zmq::context_t& context_;
    zmq::socket_t socket_;
    zmq::socket_t wake_;  // the outbox's wake-up byte arrives here
    std::shared_ptr<Outbox> outbox_;
    TransportLimits limits_;
};

// A client connection: one request, one reply, with a timeout.
class ClientConnection {
  public:
    // `curveServerKey`: the server's public key when it speaks CurveZMQ ("" otherwise).
    ClientConnection(zmq::context_t& context, const std::string& endpoint,
                     const std::string& curveServerKey = "");
    // Sends `request`; false when no reply came within `timeoutMs`.
    bool Call(const std::string& request, std::string& reply, int timeoutMs = 600000);
    // The two halves of Call, for a caller that reads past replies it does not want.
    void Send(const std::string& request);
    bool Receive(std::string& reply, int timeoutMs);

  private:
    zmq::socket_t socket_;
};

}  // namespace leaflux
