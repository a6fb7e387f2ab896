#include "server/transport.h"

#include <spdlog/spdlog.h>

#include <vector>

namespace leaflux {

RouterServer::RouterServer(zmq::context_t& context, const std::string& endpoint,
                           TransportLimits limits)
    : socket_(context, zmq::socket_type::router), limits_(limits) {
    // ZeroMQ drops the connection of a peer whose frame exceeds maxmsgsize, with no reply:
    // set it at twice the limit, so that a message merely too large gets a typed error
    // and only one absurdly large is cut off.
    socket_.set(zmq::sockopt::maxmsgsize, static_cast<int64_t>(2 * limits_.maxBytes));
    socket_.set(zmq::sockopt::linger, 0);
    socket_.bind(endpoint);
}

std::string RouterServer::Endpoint() const { return socket_.get(zmq::sockopt::last_endpoint); }

void RouterServer::Serve(const std::function<std::string(const std::string&)>& handle,
                         const std::function<std::string()>& tooLarge,
                         const std::function<bool()>& stopAfterReply,
                         const std::atomic<bool>& stop) {
    zmq::pollitem_t items[] = {{socket_.handle(), 0, ZMQ_POLLIN, 0}};
    while (!stop) {
        zmq::poll(items, 1, std::chrono::milliseconds(100));
        if (!(items[0].revents & ZMQ_POLLIN)) continue;
        // Read every frame of the message, keeping at most maxFrames of them.
        std::vector<zmq::message_t> frames;
        std::size_t bytes = 0, count = 0;
        bool more = true;
        while (more) {
            zmq::message_t frame;
            if (!socket_.recv(frame, zmq::recv_flags::none)) break;
            more = frame.more();
            ++count;
            bytes += frame.size();
            if (frames.size() < limits_.maxFrames) frames.push_back(std::move(frame));
        }
        if (frames.size() < 2) continue;  // no identity and payload: nothing to answer
        std::string reply;
        if (count > limits_.maxFrames || bytes > limits_.maxBytes) {
            spdlog::warn("refused a message of {} frames, {} bytes", count, bytes);
            reply = tooLarge();
        } else {
            const zmq::message_t& payload = frames.back();
            reply = handle(std::string(static_cast<const char*>(payload.data()), payload.size()));
        }
        // The envelope: every frame but the payload (identity, and the empty delimiter of
        // REQ and DEALER clients that send one).
        for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
            socket_.send(zmq::buffer(frames[i].data(), frames[i].size()), zmq::send_flags::sndmore);
        }
        socket_.send(zmq::buffer(reply), zmq::send_flags::none);
        if (stopAfterReply()) return;
    }
}

ClientConnection::ClientConnection(zmq::context_t& context, const std::string& endpoint)
    : socket_(context, zmq::socket_type::dealer) {
    socket_.set(zmq::sockopt::linger, 0);
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
