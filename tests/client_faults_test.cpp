// The C++ client when the daemon is slow or gone: a timeout names the endpoint, a late
// reply is never taken for the answer to a later request (on a new connection or on the
// same one), and a cycle that goes unanswered is retried once after a reconnection and a
// Resync.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "server/client.h"
#include "tests/daemon_process.h"
#include "tests/daemon_requests.h"

namespace leaflux {
namespace {

using test::CycleRequest;
using test::OpenRequest;

// A session whose cycle takes a second or more: Monte Carlo, many paths, one thread.
v1::OpenSession SlowSession() {
    v1::OpenSession open = OpenRequest().open_session();
    open.mutable_settings()->set_solver(v1::SOLVER_KIND_MONTE_CARLO);
    open.mutable_settings()->set_samples(1 << 21);
    open.mutable_settings()->set_threads(1);
    return open;
}

class ClientOnLoopback : public ::testing::Test {
  protected:
    std::int64_t CyclesOf(const std::string& session) {
        const v1::Reply state = wire_.Call(test::StatusRequest(session));
        return state.status().sessions_size() == 1 ? state.status().sessions(0).cycles() : -1;
    }
    void WaitForCycles(const std::string& session, std::int64_t cycles) {
        for (int i = 0; i < 600 && CyclesOf(session) < cycles; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        ASSERT_EQ(CyclesOf(session), cycles);
    }

    test::DaemonProcess daemon_{{"--workers", "2"}};
    test::WireClient wire_{daemon_.Endpoint()};
};

// The case: a cycle times out, its reply comes late, and the next request of the
// same client must get its own answer, not that one.
TEST_F(ClientOnLoopback, ALateReplyIsNeverTakenForTheNextAnswer) {
    Client client(daemon_.Endpoint(), "", 300);
    const std::string session = client.Open(SlowSession());
    v1::Cycle cycle = CycleRequest(session, 1).cycle();
    EXPECT_THROW(client.Cycle(cycle), ClientError);
    WaitForCycles(session, 1);  // the late reply has been sent by now
    const v1::StatusReply status = client.Status(session);
    ASSERT_EQ(status.sessions_size(), 1);
    EXPECT_EQ(status.sessions(0).cycles(), 1);
    const v1::StatusReply again = client.Status();
    EXPECT_EQ(again.sessions_size(), 0);
}

// A stand-in for leafluxd: a ROUTER on a loopback port that answers each request with the
// messages `answer` makes of it, in order. Its socket is used by its own thread alone.
class StandIn {
  public:
    using Answer = std::function<std::vector<std::string>(const v1::Request&)>;
    explicit StandIn(Answer answer) : socket_(context_, zmq::socket_type::router) {
        socket_.set(zmq::sockopt::linger, 0);
        socket_.bind("tcp://127.0.0.1:*");
        endpoint_ = socket_.get(zmq::sockopt::last_endpoint);
        thread_ = std::thread([this, answer = std::move(answer)] { Serve(answer); });
    }
    ~StandIn() {
        stop_ = true;
        thread_.join();
    }
    const std::string& Endpoint() const { return endpoint_; }

  private:
    void Serve(const Answer& answer) {
        while (!stop_) {
            zmq::pollitem_t items[] = {{socket_.handle(), 0, ZMQ_POLLIN, 0}};
            zmq::poll(items, 1, std::chrono::milliseconds(50));
            if (!(items[0].revents & ZMQ_POLLIN)) continue;
            std::vector<zmq::message_t> frames;
            if (!zmq::recv_multipart(socket_, std::back_inserter(frames))) continue;
            v1::Request request;
            request.ParseFromArray(frames.back().data(), static_cast<int>(frames.back().size()));
            for (const std::string& message : answer(request)) {
                for (std::size_t i = 0; i + 1 < frames.size(); ++i)
                    socket_.send(zmq::buffer(frames[i].data(), frames[i].size()),
                                 zmq::send_flags::sndmore);
                socket_.send(zmq::buffer(message), zmq::send_flags::none);
            }
        }
    }

    zmq::context_t context_;
    zmq::socket_t socket_;
    std::string endpoint_;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

v1::Reply StatusReplyOf(std::uint64_t requestId, int sessions) {
    v1::Reply reply;
    reply.set_version(v1::PROTOCOL_VERSION_CURRENT);
    reply.set_request_id(requestId);
    reply.mutable_status()->set_session_count(sessions);
    return reply;
}

// The case on one connection: before the answer come replies to other requests (a
// late status, a late cycle) and a message that is not a Reply; the client takes the reply
// of its own request id and drops the others.
TEST(ClientReplies, StaleRepliesAndNonRepliesOnOneConnectionAreDropped) {
    StandIn standIn([](const v1::Request& request) {
        v1::Reply lateCycle;
        lateCycle.set_request_id(request.request_id() + 1000);
        lateCycle.mutable_cycle()->set_session(std::string(32, 'a'));
        return std::vector<std::string>{
            StatusReplyOf(request.request_id() + 1, 99).SerializeAsString(),
            lateCycle.SerializeAsString(), std::string("\xff\xff\xff", 3),
            StatusReplyOf(request.request_id(), 7).SerializeAsString()};
    });
    Client client(standIn.Endpoint(), "", 5000);
    for (int i = 0; i < 3; ++i) EXPECT_EQ(client.Status().session_count(), 7) << "request " << i;
}

// No daemon on the endpoint: the client gives up within its timeout with a message that
// names the endpoint.
TEST(ClientTimeout, NoDaemonIsAnErrorNamingTheEndpointWithinTheTimeout) {
    const std::string endpoint = "tcp://127.0.0.1:9";  // discard: nothing listens there
    Client client(endpoint, "", 300);
    const auto start = std::chrono::steady_clock::now();
    try {
        client.Status();
        FAIL() << "no daemon, yet a status";
    } catch (const ClientError& e) {
        EXPECT_NE(std::string(e.what()).find(endpoint), std::string::npos) << e.what();
        EXPECT_EQ(e.Error().code(), v1::ERROR_CODE_IO);
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
}

// A request over twice the daemon's limit would be cut off by ZeroMQ, unanswered: the
// client learns the limit and refuses it with TOO_LARGE, at once, instead of timing out.
TEST(ClientLimits, ARequestOverTheDaemonsLimitIsTooLargeNotATimeout) {
    test::DaemonProcess daemon({"--max-message-mb", "1"});
    Client client(daemon.Endpoint(), "", 5000);
    v1::OpenSession open = OpenRequest().open_session();
    open.mutable_scene()->mutable_nodes(1)->set_name(std::string(3 << 20, 'n'));  // 3 MiB
    const auto start = std::chrono::steady_clock::now();
    try {
        client.Open(open);
        FAIL() << "a 3 MiB request to a daemon of 1 MiB was answered";
    } catch (const ClientError& e) {
        EXPECT_EQ(e.Error().code(), v1::ERROR_CODE_TOO_LARGE) << e.what();
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 4.0);
    EXPECT_EQ(client.Status().session_count(), 0);  // and the connection still serves
}

// Status has its own path: with every worker busy on a slow cycle it is answered at once,
// while both cycles are still solving.
TEST_F(ClientOnLoopback, StatusIsAnsweredWhileEveryWorkerSolves) {
    Client client(daemon_.Endpoint());
    const std::string a = client.Open(SlowSession()), b = client.Open(SlowSession());
    for (const std::string& session : {a, b}) {  // sent by clients that leave at once
        zmq::context_t context;
        zmq::socket_t leaving(context, zmq::socket_type::dealer);
        leaving.set(zmq::sockopt::linger, 1000);
        leaving.connect(daemon_.Endpoint());
        const std::string bytes = CycleRequest(session, 1).SerializeAsString();
        leaving.send(zmq::message_t(), zmq::send_flags::sndmore);
        leaving.send(zmq::buffer(bytes), zmq::send_flags::none);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // both workers solve
    const v1::StatusReply status = client.Status();
    EXPECT_EQ(CyclesOf(a), 0) << "Status waited for a solve";
    EXPECT_EQ(CyclesOf(b), 0) << "Status waited for a solve";
    WaitForCycles(a, 1);
    WaitForCycles(b, 1);
}

}  // namespace
}  // namespace leaflux
