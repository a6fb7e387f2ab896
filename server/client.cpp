#include "server/client.h"

#include <utility>

namespace leaflux {
namespace {

v1::Error Failure(v1::ErrorCode code, const std::string& message) {
    v1::Error error;
    error.set_code(code);
    error.set_message(message);
    return error;
}

}  // namespace

ClientError::ClientError(v1::Error error)
    : std::runtime_error(error.field().empty() ? error.message()
                                               : error.field() + ": " + error.message()),
      error_(std::move(error)) {}

Client::Client(const std::string& endpoint, const std::string& curveServerKey, int timeoutMs)
    : connection_(context_, endpoint, curveServerKey), timeoutMs_(timeoutMs) {}

v1::Reply Client::Call(v1::Request request) {
    request.set_version(v1::PROTOCOL_VERSION_CURRENT);
    request.set_request_id(nextRequest_++);
    std::string bytes, answer;
    request.SerializeToString(&bytes);
    if (!connection_.Call(bytes, answer, timeoutMs_)) {
        throw ClientError(Failure(v1::ERROR_CODE_IO, "no reply from leafluxd within " +
                                                         std::to_string(timeoutMs_ / 1000) + " s"));
    }
    v1::Reply reply;
    if (!reply.ParseFromString(answer)) {
        throw ClientError(Failure(v1::ERROR_CODE_PARSE, "the reply is not a leaflux.v1.Reply"));
    }
    return reply;
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
    return Expect(std::move(request), v1::Reply::kOpened).opened().session();
}

v1::CycleResult Client::Cycle(const v1::Cycle& cycle) {
    v1::Request request;
    *request.mutable_cycle() = cycle;
    return std::move(*Expect(std::move(request), v1::Reply::kCycle).mutable_cycle());
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
}

void Client::Close(const std::string& session) {
    v1::Request request;
    request.mutable_close_session()->set_session(session);
    Expect(std::move(request), v1::Reply::kDone);
}

void Client::Shutdown() {
    v1::Request request;
    request.mutable_shutdown();
    Expect(std::move(request), v1::Reply::kDone);
}

}  // namespace leaflux
