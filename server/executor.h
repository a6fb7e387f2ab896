// Runs jobs on a few worker threads: the jobs of one key (a session) one at a time, in the
// order they came; jobs of different keys, and keyless ones, in parallel. So a slow solve
// of one session holds back that session's next requests and nothing else.
#pragma once

#include <condition_variable>
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

    // An empty key: a job with no order to keep.
    void Submit(const std::string& key, std::function<void()> job);

  private:
    void Work();

    std::mutex mutex_;
    std::condition_variable wake_;
    std::map<std::string, std::deque<std::function<void()>>> queues_;
    std::deque<std::string> ready_;  // keys with a job to run and none running
    std::set<std::string> busy_;
    std::deque<std::function<void()>> free_;  // keyless jobs
    bool stopping_ = false;
    std::vector<std::thread> workers_;
};

}  // namespace leaflux
