// Runs jobs on a few worker threads: the jobs of one key (a session) one at a time, in the
// order they came; jobs of different keys, and keyless ones, in parallel. So a slow solve
// of one session holds back that session's next requests and nothing else.
//
// A job has a way to be refused: when the daemon stops, the jobs still queued are refused
// (CancelQueued), never run; the ones running are the caller's to wait for or abandon.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace leaflux {

class KeyedExecutor {
  public:
    explicit KeyedExecutor(int threads);
    ~KeyedExecutor();  // runs what is queued, then joins
    KeyedExecutor(const KeyedExecutor&) = delete;
    KeyedExecutor& operator=(const KeyedExecutor&) = delete;

    // An empty key: a job with no order to keep. `refuse` is called instead of `run` when
    // the job is cancelled before it starts.
    void Submit(const std::string& key, std::function<void()> run,
                std::function<void()> refuse = {});

    // Refuses every job not yet started (outside the executor's lock) and returns how many.
    std::size_t CancelQueued();

  private:
    struct Job {
        std::function<void()> run, refuse;
    };
    void Work();

    std::mutex mutex_;
    std::condition_variable wake_;
    std::map<std::string, std::deque<Job>> queues_;
    std::deque<std::string> ready_;  // keys with a job to run and none running
    std::set<std::string> busy_;
    std::deque<Job> free_;  // keyless jobs
    bool stopping_ = false;
    std::vector<std::thread> workers_;
};

}  // namespace leaflux
