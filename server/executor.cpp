#include "server/executor.h"

namespace leaflux {

KeyedExecutor::KeyedExecutor(int threads) {
    for (int i = 0; i < std::max(1, threads); ++i) workers_.emplace_back([this] { Work(); });
}

KeyedExecutor::~KeyedExecutor() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread& worker : workers_) worker.join();
}

void KeyedExecutor::Submit(const std::string& key, std::function<void()> job) {
    {
        std::lock_guard lock(mutex_);
        if (key.empty()) {
            free_.push_back(std::move(job));
        } else {
            auto& queue = queues_[key];
            queue.push_back(std::move(job));
            if (queue.size() == 1 && !busy_.count(key)) ready_.push_back(key);
        }
    }
    wake_.notify_one();
}

void KeyedExecutor::Work() {
    std::unique_lock lock(mutex_);
    for (;;) {
        wake_.wait(lock, [this] { return stopping_ || !free_.empty() || !ready_.empty(); });
        if (!free_.empty()) {
            std::function<void()> job = std::move(free_.front());
            free_.pop_front();
            lock.unlock();
            job();
            lock.lock();
            continue;
        }
        if (!ready_.empty()) {
            const std::string key = ready_.front();
            ready_.pop_front();
            auto& queue = queues_[key];
            std::function<void()> job = std::move(queue.front());
            queue.pop_front();
            busy_.insert(key);
            lock.unlock();
            job();
            lock.lock();
            busy_.erase(key);
            if (queues_[key].empty()) {
                queues_.erase(key);
            } else {
                ready_.push_back(key);
                wake_.notify_one();
            }
            continue;
        }
        if (stopping_) return;
    }
}

}  // namespace leaflux
