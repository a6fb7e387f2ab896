// ZeroMQ transport of leafluxd: a ROUTER socket that reads whole multipart messages (with
// a cap on frames and bytes), hands the last frame to a handler and sends the reply back
// with the same envelope. It knows nothing of protobuf or of the solver.
#pragma once

#include <atomic>
#include <functional>
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

class RouterServer {
  public:
    // Binds `endpoint` (e.g. tcp://127.0.0.1:5555, tcp://127.0.0.1:* for any port).
    RouterServer(zmq::context_t& context, const std::string& endpoint, TransportLimits limits = {},
                 const std::string& curveSecretKey = "");

    // The endpoint actually bound (with the port chosen for a "*").
    std::string Endpoint() const;

    // Called once per message, from any thread, with its reply.
    using Respond = std::function<void(std::string reply)>;
    using Dispatch = std::function<void(std::string payload, Respond respond)>;

    // Serves until `stop` is set (checked every 100 ms) or, after a reply has been sent,
    // `stopAfterReply` says so. `dispatch` may answer later from another thread; the socket
    // itself is only ever used by the thread that serves. `tooLarge` makes the reply to a
    // message over the limits.
    void Serve(const Dispatch& dispatch, const std::function<std::string()>& tooLarge,
               const std::function<bool()>& stopAfterReply, const std::atomic<bool>& stop);

    // A Dispatch that answers at once with `handle`.
    static Dispatch Synchronous(std::function<std::string(const std::string&)> handle);

  private:
    zmq::context_t& context_;
    zmq::socket_t socket_;
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

  private:
    zmq::socket_t socket_;
};

}  // namespace leaflux
