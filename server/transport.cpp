#include "server/transport.h"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstdint>
#include <deque>
#include <fstream>
#include <memory>
#include <mutex>
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

RouterServer::RouterServer(zmq::context_t& context, const std::string& endpoint,
                           TransportLimits limits, const std::string& curveSecretKey)
    : context_(context), socket_(context, zmq::socket_type::router), limits_(limits) {
    // ZeroMQ drops the connection of a peer whose frame exceeds maxmsgsize, with no reply:
    // set it at twice the limit, so that a message merely too large gets a typed error
    // and only one absurdly large is cut off.
    socket_.set(zmq::sockopt::maxmsgsize, static_cast<int64_t>(2 * limits_.maxBytes));
    socket_.set(zmq::sockopt::linger, 0);
    if (!curveSecretKey.empty()) {
        socket_.set(zmq::sockopt::curve_server, true);
        socket_.set(zmq::sockopt::curve_secretkey, curveSecretKey);
    }
    socket_.bind(endpoint);
}

std::string RouterServer::Endpoint() const { return socket_.get(zmq::sockopt::last_endpoint); }

RouterServer::Dispatch RouterServer::Synchronous(
    std::function<std::string(const std::string&)> handle) {
    return [handle = std::move(handle)](std::string payload, Respond respond) {
        respond(handle(payload));
    };
}

void RouterServer::Serve(const Dispatch& dispatch, const std::function<std::string()>& tooLarge,
                         const std::function<bool()>& stopAfterReply,
                         const std::atomic<bool>& stop) {
    // Replies come back through an outbox; a byte on an inproc pair wakes the loop.
    struct Outbox {
        std::mutex mutex;
        std::deque<std::pair<std::vector<std::string>, std::string>> replies;
        zmq::socket_t push;
    };
    const std::string wakeEndpoint =
        "inproc://leaflux-outbox-" + std::to_string(reinterpret_cast<std::uintptr_t>(this));
    zmq::socket_t pull(context_, zmq::socket_type::pull);
    pull.bind(wakeEndpoint);
    auto outbox = std::make_shared<Outbox>();
    outbox->push = zmq::socket_t(context_, zmq::socket_type::push);
    outbox->push.set(zmq::sockopt::linger, 0);
    outbox->push.connect(wakeEndpoint);

    zmq::pollitem_t items[] = {{socket_.handle(), 0, ZMQ_POLLIN, 0},
                               {pull.handle(), 0, ZMQ_POLLIN, 0}};
    while (!stop) {
        try {
            zmq::poll(items, 2, std::chrono::milliseconds(100));
        } catch (const zmq::error_t& e) {
            if (e.num() == EINTR) continue;  // a signal (SIGINT, SIGTERM): `stop` says what next
            throw;
        }
        if (items[1].revents & ZMQ_POLLIN) {
            zmq::message_t ignored;
            while (AgainOnSignal([&] { return pull.recv(ignored, zmq::recv_flags::dontwait); })) {
            }
            std::deque<std::pair<std::vector<std::string>, std::string>> ready;
            {
                std::lock_guard lock(outbox->mutex);
                ready.swap(outbox->replies);
            }
            for (auto& [envelope, reply] : ready) {
                for (const std::string& frame : envelope) {
                    AgainOnSignal(
                        [&] { return socket_.send(zmq::buffer(frame), zmq::send_flags::sndmore); });
                }
                AgainOnSignal(
                    [&] { return socket_.send(zmq::buffer(reply), zmq::send_flags::none); });
                if (stopAfterReply()) return;
            }
        }
        if (!(items[0].revents & ZMQ_POLLIN)) continue;
        // Read every frame of the message, keeping at most maxFrames of them.
        std::vector<zmq::message_t> frames;
        std::size_t bytes = 0, count = 0;
        bool more = true;
        while (more) {
            zmq::message_t frame;
            if (!AgainOnSignal([&] { return socket_.recv(frame, zmq::recv_flags::none); })) break;
            more = frame.more();
            ++count;
            bytes += frame.size();
            if (frames.size() < limits_.maxFrames) frames.push_back(std::move(frame));
        }
        if (frames.size() < 2) continue;  // no identity and payload: nothing to answer
        // The envelope: every frame but the payload (identity, and the empty delimiter of
        // REQ and DEALER clients that send one).
        std::vector<std::string> envelope;
        for (std::size_t i = 0; i + 1 < frames.size(); ++i)
            envelope.push_back(frames[i].to_string());
        Respond respond = [outbox, envelope](std::string reply) {
            std::lock_guard lock(outbox->mutex);
            outbox->replies.emplace_back(envelope, std::move(reply));
            outbox->push.send(zmq::str_buffer("!"), zmq::send_flags::dontwait);
        };
        if (count > limits_.maxFrames || bytes > limits_.maxBytes) {
            spdlog::warn("refused a message of {} frames, {} bytes", count, bytes);
            respond(tooLarge());
        } else {
            dispatch(frames.back().to_string(), std::move(respond));
        }
    }
}

ClientConnection::ClientConnection(zmq::context_t& context, const std::string& endpoint,
                                   const std::string& curveServerKey)
    : socket_(context, zmq::socket_type::dealer) {
    socket_.set(zmq::sockopt::linger, 0);
    if (!curveServerKey.empty()) {
        // An ephemeral client key pair: the server authenticates itself, not the client.
        const CurveKeyPair mine = CurveKeyPair::Generate();
        socket_.set(zmq::sockopt::curve_serverkey, curveServerKey);
        socket_.set(zmq::sockopt::curve_publickey, mine.publicKey);
        socket_.set(zmq::sockopt::curve_secretkey, mine.secretKey);
    }
    socket_.connect(endpoint);
}

bool ClientConnection::Call(const std::string& request, std::string& reply, int timeoutMs) {
    socket_.send(zmq::message_t(), zmq::send_flags::sndmore);  // the delimiter
    socket_.send(zmq::buffer(request), zmq::send_flags::none);
    zmq::pollitem_t items[] = {{socket_.handle(), 0, ZMQ_POLLIN, 0}};
    zmq::poll(items, 1, std::chrono::milliseconds(timeoutMs));
    if (!(items[0].revents & ZMQ_POLLIN)) return false;
    std::vector<zmq::message_t> frames;
    const auto received = zmq::recv_multipart(socket_, std::back_inserter(frames));
    if (!received || frames.empty()) return false;
    reply.assign(static_cast<const char*>(frames.back().data()), frames.back().size());
    return true;
}

}  // namespace leaflux
