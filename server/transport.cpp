#include "server/transport.h"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstdint>
#include <deque>
#include <fstream>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace leaflux {
namespace {

// A read or send interrupted by a signal (SIGINT, SIGTERM) is made again: the serving
// loop sees `stop` at its next poll, never after half a message.
template <class Call>
auto AgainOnSignal(Call call) {
    for (;;) {
        try {
            return call();
        } catch (const zmq::error_t& e) {
            if (e.num() != EINTR) throw;
        }
    }
}

}  // namespace

CurveKeyPair CurveKeyPair::Generate() {
    char publicKey[41], secretKey[41];
    if (zmq_curve_keypair(publicKey, secretKey) != 0) throw zmq::error_t();
    return {publicKey, secretKey};
}

std::optional<std::string> ReadCurveKey(const std::string& path) {
    std::ifstream in(path);
    std::string key;
    if (!(in >> key) || key.size() != 40) return std::nullopt;
    return key;
}

bool IsLoopback(const std::string& endpoint) {
    for (const char* prefix :
         {"tcp://127.", "tcp://localhost:", "tcp://[::1]:", "ipc://", "inproc://"}) {
        if (endpoint.rfind(prefix, 0) == 0) return true;
    }
    return false;
}

std::string EndpointProblem(const std::string& endpoint) {
    const std::size_t scheme = endpoint.find("://");
    if (scheme == std::string::npos) {
        return endpoint + " has no transport: write tcp://" + endpoint +
               " (or ipc://PATH, inproc://NAME)";
    }
    const std::string transport = endpoint.substr(0, scheme);
    if (transport != "tcp" && transport != "ipc" && transport != "inproc") {
        return endpoint + ": unknown transport '" + transport + "' (tcp, ipc or inproc)";
    }
    return "";
}

// Replies come back through an outbox from any thread; a byte on an inproc pair wakes the
// serving loop. Once closed, replies are dropped.
struct RouterServer::Outbox {
    std::mutex mutex;
    std::deque<std::pair<std::vector<std::string>, std::string>> replies;
    zmq::socket_t push;
    bool closed = false;
};

RouterServer::RouterServer(zmq::context_t& context, const std::string& endpoint,
                           TransportLimits limits, const std::string& curveSecretKey)
    : context_(context),
      socket_(context, zmq::socket_type::router),
      wake_(context, zmq::socket_type::pull),
      outbox_(std::make_shared<Outbox>()),
      limits_(limits) {
    if (const std::string problem = EndpointProblem(endpoint); !problem.empty())
        throw std::runtime_error(problem);
    // ZeroMQ reads a multipart message whole before handing over any frame, and drops the
    // connection of a peer whose frame exceeds maxmsgsize, unanswered. At twice the limit,
    // a message merely too large gets its typed error and only an absurd frame is cut off;
    // the whole message is counted as it is read (Serve).
    socket_.set(zmq::sockopt::maxmsgsize, static_cast<int64_t>(2 * limits_.maxBytes));
    socket_.set(zmq::sockopt::linger, 0);
    if (endpoint.find('[') != std::string::npos) socket_.set(zmq::sockopt::ipv6, true);
    if (!curveSecretKey.empty()) {
        socket_.set(zmq::sockopt::curve_server, true);
        socket_.set(zmq::sockopt::curve_secretkey, curveSecretKey);
    }
    try {
        socket_.bind(endpoint);
    } catch (const zmq::error_t& e) {
        throw std::runtime_error("cannot bind " + endpoint + ": " + e.what());
    }
    const std::string wakeEndpoint =
        "inproc://leaflux-outbox-" + std::to_string(reinterpret_cast<std::uintptr_t>(this));
    wake_.bind(wakeEndpoint);
    outbox_->push = zmq::socket_t(context_, zmq::socket_type::push);
    outbox_->push.set(zmq::sockopt::linger, 0);
    outbox_->push.connect(wakeEndpoint);
}

RouterServer::~RouterServer() { Close(std::chrono::milliseconds(0)); }

std::string RouterServer::Endpoint() const { return socket_.get(zmq::sockopt::last_endpoint); }

RouterServer::Dispatch RouterServer::Synchronous(
    std::function<std::string(const std::string&)> handle) {
    return [handle = std::move(handle)](std::string payload, Respond respond) {
        respond(handle(payload));
    };
}

void RouterServer::SendReady() {
    std::deque<std::pair<std::vector<std::string>, std::string>> ready;
    {
        std::lock_guard lock(outbox_->mutex);
        ready.swap(outbox_->replies);
    }
    for (auto& [envelope, reply] : ready) {
        for (const std::string& frame : envelope) {
            AgainOnSignal(
                [&] { return socket_.send(zmq::buffer(frame), zmq::send_flags::sndmore); });
        }
        AgainOnSignal([&] { return socket_.send(zmq::buffer(reply), zmq::send_flags::none); });
    }
}

void RouterServer::Close(std::chrono::milliseconds linger) {
    if (!socket_) return;
    SendReady();
    {
        std::lock_guard lock(outbox_->mutex);
        outbox_->closed = true;
        outbox_->replies.clear();
        outbox_->push.close();
    }
    wake_.close();
    socket_.set(zmq::sockopt::linger, static_cast<int>(linger.count()));
    socket_.close();
}

void RouterServer::Serve(const Dispatch& dispatch, const TooLarge& tooLarge,
                         const std::function<bool()>& stopAfterReply,
                         const std::function<bool()>& stop) {
    std::shared_ptr<Outbox> outbox = outbox_;
    zmq::pollitem_t items[] = {{socket_.handle(), 0, ZMQ_POLLIN, 0},
                               {wake_.handle(), 0, ZMQ_POLLIN, 0}};
    SendReady();
    while (!stop()) {
        try {
            zmq::poll(items, 2, std::chrono::milliseconds(100));
        } catch (const zmq::error_t& e) {
            if (e.num() == EINTR) continue;  // a signal (SIGINT, SIGTERM): `stop` says what next
            throw;
        }
        if (items[1].revents & ZMQ_POLLIN) {
            zmq::message_t ignored;
            while (AgainOnSignal([&] { return wake_.recv(ignored, zmq::recv_flags::dontwait); })) {
            }
            SendReady();
            if (stopAfterReply()) return;
        }
        if (!(items[0].revents & ZMQ_POLLIN)) continue;
        // Read every frame of the message, counting them all and keeping at most maxFrames,
        // none once the message is over the byte limit.
        std::vector<zmq::message_t> frames;
        std::size_t bytes = 0, count = 0;
        std::string head;
        bool more = true;
        while (more) {
            zmq::message_t frame;
            if (!AgainOnSignal([&] { return socket_.recv(frame, zmq::recv_flags::none); })) break;
            more = frame.more();
            ++count;
            bytes += frame.size();
            head.assign(static_cast<const char*>(frame.data()),
                        std::min<std::size_t>(frame.size(), 64));
            const bool over = count > limits_.maxFrames || bytes > limits_.maxBytes;
            if (!over) {
                frames.push_back(std::move(frame));
            } else if (frames.size() > 1) {
                // Only what the answer needs: the identity, and the delimiter if any.
                frames.resize(frames[1].size() == 0 ? 2 : 1);
            }
        }
        if (frames.empty()) continue;
        const bool over = count > limits_.maxFrames || bytes > limits_.maxBytes;
        if (!over && frames.size() < 2) continue;  // no identity and payload: nothing to answer
        // The envelope: every frame but the payload (identity, and the empty delimiter of
        // REQ and DEALER clients that send one); of a refused message, the identity and
        // the delimiter when it sent one.
        std::vector<std::string> envelope;
        for (std::size_t i = 0; i + 1 < frames.size() || (over && i < frames.size()); ++i)
            envelope.push_back(frames[i].to_string());
        Respond respond = [outbox, envelope](std::string reply) {
            std::lock_guard lock(outbox->mutex);
            if (outbox->closed) return;
            outbox->replies.emplace_back(envelope, std::move(reply));
            outbox->push.send(zmq::str_buffer("!"), zmq::send_flags::dontwait);
        };
        if (over) {
            spdlog::warn("refused a message of {} frames, {} bytes (limits: {} frames, {} bytes)",
                         count, bytes, limits_.maxFrames, limits_.maxBytes);
            respond(tooLarge({bytes, count, head}));
        } else {
            dispatch(frames.back().to_string(), std::move(respond));
        }
    }
}

ClientConnection::ClientConnection(zmq::context_t& context, const std::string& endpoint,
                                   const std::string& curveServerKey)
    : socket_(context, zmq::socket_type::dealer) {
    socket_.set(zmq::sockopt::linger, 0);
    if (endpoint.find('[') != std::string::npos) socket_.set(zmq::sockopt::ipv6, true);
    if (!curveServerKey.empty()) {
        // An ephemeral client key pair: the server authenticates itself, not the client.
        const CurveKeyPair mine = CurveKeyPair::Generate();
        socket_.set(zmq::sockopt::curve_serverkey, curveServerKey);
        socket_.set(zmq::sockopt::curve_publickey, mine.publicKey);
        socket_.set(zmq::sockopt::curve_secretkey, mine.secretKey);
    }
    if (const std::string problem = EndpointProblem(endpoint); !problem.empty())
        throw std::runtime_error(problem);
    socket_.connect(endpoint);
}

void ClientConnection::Send(const std::string& request) {
    socket_.send(zmq::message_t(), zmq::send_flags::sndmore);  // the delimiter
    socket_.send(zmq::buffer(request), zmq::send_flags::none);
}

bool ClientConnection::Receive(std::string& reply, int timeoutMs) {
    zmq::pollitem_t items[] = {{socket_.handle(), 0, ZMQ_POLLIN, 0}};
    zmq::poll(items, 1, std::chrono::milliseconds(std::max(0, timeoutMs)));
    if (!(items[0].revents & ZMQ_POLLIN)) return false;
    std::vector<zmq::message_t> frames;
    const auto received = zmq::recv_multipart(socket_, std::back_inserter(frames));
    if (!received || frames.empty()) return false;
    reply.assign(static_cast<const char*>(frames.back().data()), frames.back().size());
    return true;
}

bool ClientConnection::Call(const std::string& request, std::string& reply, int timeoutMs) {
    Send(request);
    return Receive(reply, timeoutMs);
}

}  // namespace leaflux
