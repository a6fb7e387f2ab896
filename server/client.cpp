#include "server/client.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <utility>

namespace leaflux {
namespace {

v1::Error Failure(v1::ErrorCode code, const std::string& message) {
    v1::Error error;
    error.set_code(code);
    error.set_message(message);
    return error;
}

std::int64_t OrgansOf(const google::protobuf::RepeatedPtrField<v1::Node>& nodes) {
    return std::count_if(nodes.begin(), nodes.end(),
                         [](const v1::Node& n) { return n.has_organ(); });
}

}  // namespace

ClientError::ClientError(v1::Error error)
    : std::runtime_error(error.field().empty() ? error.message()
                                               : error.field() + ": " + error.message()),
      error_(std::move(error)) {}

Client::Client(const std::string& endpoint, const std::string& curveServerKey,
               ClientTimeouts timeouts)
    : endpoint_(endpoint), curveServerKey_(curveServerKey), timeouts_(timeouts) {
    Reconnect();
}

void Client::Reconnect() {
    maxMessageBytes_.reset();  // perhaps another daemon now
    try {
        connection_ = std::make_unique<ClientConnection>(context_, endpoint_, curveServerKey_);
    } catch (const std::exception& e) {
        throw ClientError(Failure(v1::ERROR_CODE_INVALID_ARGUMENT, e.what()));
    }
}

int Client::TimeoutMs(const v1::Request& request) const {
    std::int64_t organs = 0;
    switch (request.body_case()) {
        case v1::Request::kOpenSession:
            organs = OrgansOf(request.open_session().scene().nodes());
            break;
        case v1::Request::kResync:
            organs = OrgansOf(request.resync().scene().nodes());
            break;
        case v1::Request::kCycle: {
            const auto it = organs_.find(request.cycle().session());
            organs =
                (it == organs_.end() ? 0 : it->second) + OrgansOf(request.cycle().delta().added());
            break;
        }
        case v1::Request::kRender: {  // the session's ray engine built, then the picture
            const auto it = organs_.find(request.render().session());
            organs = it == organs_.end() ? 0 : it->second;
            break;
        }
        default:
            return timeouts_.statusMs;
    }
    return static_cast<int>(std::min<std::int64_t>(
        timeouts_.sceneMs + organs * timeouts_.perOrganMs, std::int64_t{1} << 30));
}

v1::Reply Client::Call(v1::Request request) {
    request.set_version(v1::PROTOCOL_VERSION_CURRENT);
    const std::uint64_t id = nextRequest_++;
    request.set_request_id(id);
    const int timeoutMs = TimeoutMs(request);
    std::string bytes, answer;
    request.SerializeToString(&bytes);
    constexpr std::size_t kAskLimitBytes = 1 << 20;
    if (bytes.size() > kAskLimitBytes && !request.has_status()) {
        if (!maxMessageBytes_) maxMessageBytes_ = Status().max_message_bytes();
        if (*maxMessageBytes_ > 0 && bytes.size() > static_cast<std::size_t>(*maxMessageBytes_)) {
            throw ClientError(Failure(
                v1::ERROR_CODE_TOO_LARGE,
                fmt::format("the request of {} bytes exceeds the limit of leafluxd at {}, {} "
                            "bytes (--max-message-mb): not sent",
                            bytes.size(), endpoint_, *maxMessageBytes_)));
        }
    }
    connection_->Send(bytes);
    using Clock = std::chrono::steady_clock;
    const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(timeoutMs);
    for (;;) {
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
        if (!connection_->Receive(answer, static_cast<int>(left.count()))) {
            Reconnect();  // a late reply must not be read as the answer to the next request
            throw ClientError(Failure(
                v1::ERROR_CODE_IO,
                fmt::format("no reply from leafluxd at {} within {:g} s (is it running? busy "
                            "with a long solve? is the request, {} bytes, over its "
                            "--max-message-mb?)",
                            endpoint_, timeoutMs / 1000.0, bytes.size())));
        }
        v1::Reply reply;
        if (!reply.ParseFromString(answer)) {  // not a Reply, so not the answer either
            spdlog::warn("{}: dropped a message of {} bytes that is not a leaflux.v1.Reply",
                         endpoint_, answer.size());
            continue;
        }
        // Id 0: the daemon could not read the request's id (it did not decode).
        if (reply.request_id() == id || (reply.request_id() == 0 && reply.has_error())) {
            if (request.has_cycle() && reply.has_cycle()) {
                organs_[request.cycle().session()] += OrgansOf(request.cycle().delta().added());
            }
            return reply;
        }
        spdlog::debug("{}: dropped a late reply to request {}", endpoint_, reply.request_id());
    }
}

v1::Reply Client::Expect(v1::Request request, v1::Reply::BodyCase expected) {
    v1::Reply reply = Call(std::move(request));
    if (reply.has_error()) throw ClientError(reply.error());
    if (reply.body_case() != expected) {
        throw ClientError(Failure(v1::ERROR_CODE_INTERNAL, "unexpected reply type"));
    }
    return reply;
}

std::string Client::Open(const v1::OpenSession& open) {
    v1::Request request;
    *request.mutable_open_session() = open;
    const std::string session = Expect(std::move(request), v1::Reply::kOpened).opened().session();
    organs_[session] = OrgansOf(open.scene().nodes());
    return session;
}

v1::CycleResult Client::Cycle(const v1::Cycle& cycle) {
    v1::Request request;
    *request.mutable_cycle() = cycle;
    return std::move(*Expect(std::move(request), v1::Reply::kCycle).mutable_cycle());
}

v1::CycleResult Client::Cycle(const v1::Cycle& cycle, const std::function<v1::Resync()>& resync) {
    try {
        return Cycle(cycle);
    } catch (const ClientError& e) {
        const v1::ErrorCode code = e.Error().code();
        if (code != v1::ERROR_CODE_IO && code != v1::ERROR_CODE_UNKNOWN_SESSION) throw;
        spdlog::warn("cycle {} of session {}: {}; reconnecting, resyncing and sending it again",
                     cycle.number(), cycle.session(), e.what());
    }
    Reconnect();
    Resync(resync());
    return Cycle(cycle);
}

v1::StatusReply Client::Status(const std::string& session) {
    v1::Request request;
    request.mutable_status()->set_session(session);
    return Expect(std::move(request), v1::Reply::kStatus).status();
}

void Client::Resync(const v1::Resync& resync) {
    v1::Request request;
    *request.mutable_resync() = resync;
    Expect(std::move(request), v1::Reply::kOpened);
    organs_[resync.session()] = OrgansOf(resync.scene().nodes());
}

void Client::Close(const std::string& session) {
    v1::Request request;
    request.mutable_close_session()->set_session(session);
    Expect(std::move(request), v1::Reply::kDone);
    organs_.erase(session);
}

v1::Picture Client::Render(const v1::RenderRequest& render) {
    v1::Request request;
    *request.mutable_render() = render;
    return Expect(std::move(request), v1::Reply::kPicture).picture();
}

void Client::Shutdown() {
    v1::Request request;
    request.mutable_shutdown();
    Expect(std::move(request), v1::Reply::kDone);
}

}  // namespace leaflux
