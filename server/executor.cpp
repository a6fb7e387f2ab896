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

void KeyedExecutor::Submit(const std::string& key, std::function<void()> run,
                           std::function<void()> refuse) {
    {
        std::lock_guard lock(mutex_);
        if (key.empty()) {
            free_.push_back({std::move(run), std::move(refuse)});
        } else {
            auto& queue = queues_[key];
            queue.push_back({std::move(run), std::move(refuse)});
            if (queue.size() == 1 && !busy_.count(key)) ready_.push_back(key);
        }
    }
    wake_.notify_one();
}

std::size_t KeyedExecutor::CancelQueued() {
    std::vector<Job> cancelled;
    {
        std::lock_guard lock(mutex_);
        for (Job& job : free_) cancelled.push_back(std::move(job));
        free_.clear();
        for (auto& [key, queue] : queues_) {
            for (Job& job : queue) cancelled.push_back(std::move(job));
            queue.clear();
        }
        ready_.clear();  // a busy key's worker finds its queue empty and erases it
        for (auto it = queues_.begin(); it != queues_.end();) {
            it = busy_.count(it->first) ? std::next(it) : queues_.erase(it);
        }
    }
    for (Job& job : cancelled) {
        if (job.refuse) job.refuse();
    }
    return cancelled.size();
}

void KeyedExecutor::Work() {
    std::unique_lock lock(mutex_);
    for (;;) {
        wake_.wait(lock, [this] { return stopping_ || !free_.empty() || !ready_.empty(); });
        if (!free_.empty()) {
            Job job = std::move(free_.front());
            free_.pop_front();
            lock.unlock();
            job.run();
            lock.lock();
            continue;
        }
        if (!ready_.empty()) {
            const std::string key = ready_.front();
            ready_.pop_front();
            auto& queue = queues_[key];
            Job job = std::move(queue.front());
            queue.pop_front();
            busy_.insert(key);
            lock.unlock();
            job.run();
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
