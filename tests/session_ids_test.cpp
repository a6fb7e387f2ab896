// Session ids are credentials: 128 random bits, never issued twice (in one daemon or
// across restarts), never disclosed to other clients; OpenSession never replaces a
// session and Resync replaces only the session of its own id. On leafluxd processes.
#include <gtest/gtest.h>

#include <regex>
#include <set>
#include <string>

#include "tests/daemon_process.h"
#include "tests/daemon_requests.h"

namespace leaflux {
namespace {

using test::CycleRequest;
using test::OpenRequest;
using test::ResyncRequest;

// The daemon as a process, and a connection to it.
struct LiveDaemon {
    LiveDaemon() : client(process.Endpoint()) {}
    v1::Reply Handle(const v1::Request& request) { return client.Call(request); }
    test::DaemonProcess process;
    test::WireClient client;
};

int OrgansLit(LiveDaemon& daemon, const std::string& session, std::int64_t number) {
    const v1::Reply reply = daemon.Handle(CycleRequest(session, number));
    EXPECT_TRUE(reply.has_cycle()) << reply.ShortDebugString();
    return reply.cycle().organs_size();
}

TEST(SessionIds, AreRandom128BitHexAndNeverRepeatAcrossDaemons) {
    const std::regex form("[0-9a-f]{32}");
    std::set<std::string> seen;
    for (int restart = 0; restart < 2; ++restart) {
        LiveDaemon daemon;
        for (int i = 0; i < 40; ++i) {
            const std::string id = daemon.Handle(OpenRequest()).opened().session();
            EXPECT_TRUE(std::regex_match(id, form)) << id;
            EXPECT_TRUE(seen.insert(id).second) << id << " issued twice";
            daemon.Handle([&] {
                v1::Request close = test::StatusRequest();
                close.mutable_close_session()->set_session(id);
                return close;
            }());
        }
    }
}

// The case: after a restart a client resyncs its session (3 organs); a newcomer's
// OpenSession (1 organ) must get another id, and the first client's next cycle its own
// plant's light.
TEST(SessionIds, AnOpenAfterARestartNeverTakesAResyncedSession) {
    std::string id;
    {
        LiveDaemon first;
        first.Handle(OpenRequest());
        id = first.Handle(OpenRequest(3)).opened().session();
        ASSERT_EQ(OrgansLit(first, id, 1), 3);
    }  // killed (SIGKILL)
    LiveDaemon second;
    const v1::Reply resynced = second.Handle(ResyncRequest(id, 3));
    ASSERT_TRUE(resynced.has_opened()) << resynced.ShortDebugString();
    EXPECT_EQ(resynced.opened().session(), id);
    for (int i = 0; i < 5; ++i) {
        const std::string other = second.Handle(OpenRequest(1)).opened().session();
        EXPECT_NE(other, id);
        EXPECT_EQ(OrgansLit(second, other, 1), 1);
    }
    EXPECT_EQ(OrgansLit(second, id, 2), 3) << "the resynced session was replaced";
}

TEST(SessionIds, ResyncReplacesOnlyTheSessionOfItsId) {
    LiveDaemon daemon;
    const std::string a = daemon.Handle(OpenRequest(1)).opened().session();
    const std::string b = daemon.Handle(OpenRequest(2)).opened().session();
    const v1::Reply resynced = daemon.Handle(ResyncRequest(a, 3));
    ASSERT_TRUE(resynced.has_opened()) << resynced.ShortDebugString();
    EXPECT_EQ(resynced.opened().session(), a);
    EXPECT_EQ(OrgansLit(daemon, a, 1), 3);
    EXPECT_EQ(OrgansLit(daemon, b, 1), 2);
}

// Ids a daemon could never have issued ("s1", short, upper-case) are refused: a Resync
// cannot plant a guessable id for another client to collide with.
TEST(SessionIds, ResyncRefusesIdsTheDaemonCouldNotHaveIssued) {
    LiveDaemon daemon;
    for (const std::string& id : {std::string("s1"), std::string("s2"), std::string(31, 'a'),
                                  std::string(32, 'A'), std::string(33, 'a')}) {
        const v1::Reply reply = daemon.Handle(ResyncRequest(id));
        ASSERT_TRUE(reply.has_error()) << id;
        EXPECT_EQ(reply.error().code(), v1::ERROR_CODE_INVALID_ARGUMENT) << id;
        EXPECT_EQ(reply.error().field(), "session");
    }
}

// The daemon's status counts sessions but names none: ids are credentials.
TEST(SessionIds, TheDaemonsStatusDisclosesNoSessionId) {
    LiveDaemon daemon;
    const std::string a = daemon.Handle(OpenRequest()).opened().session();
    const std::string b = daemon.Handle(OpenRequest()).opened().session();
    const v1::Reply status = daemon.Handle(test::StatusRequest());
    ASSERT_TRUE(status.has_status()) << status.ShortDebugString();
    const std::string bytes = status.SerializeAsString();
    EXPECT_EQ(bytes.find(a), std::string::npos);
    EXPECT_EQ(bytes.find(b), std::string::npos);
    EXPECT_EQ(status.status().sessions_size(), 0);
    // One's own session, asked by its id, is reported.
    const v1::Reply mine = daemon.Handle(test::StatusRequest(a));
    ASSERT_EQ(mine.status().sessions_size(), 1);
    EXPECT_EQ(mine.status().sessions(0).session(), a);
}

}  // namespace
}  // namespace leaflux
