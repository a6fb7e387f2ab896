#include "solver/util/interned_string.h"

#include <mutex>
#include <unordered_map>

namespace leaflux {
namespace {

// Every text held, weakly: a text is freed with its last holder, its entry once the table
// has doubled since it last dropped the freed ones.
class Table {
  public:
    std::shared_ptr<const std::string> Intern(std::string_view text) {
        std::lock_guard lock(mutex_);
        std::weak_ptr<const std::string>& entry = entries_[std::string(text)];
        if (auto held = entry.lock()) return held;
        auto made = std::make_shared<const std::string>(text);
        entry = made;
        if (entries_.size() > 2 * keptAtSweep_ + 64) Sweep();
        return made;
    }

  private:
    void Sweep() {
        std::erase_if(entries_, [](const auto& entry) { return entry.second.expired(); });
        keptAtSweep_ = entries_.size();
    }

    std::mutex mutex_;
    std::unordered_map<std::string, std::weak_ptr<const std::string>> entries_;
    std::size_t keptAtSweep_ = 0;
};

}  // namespace

InternedString::InternedString(std::string_view text) {
    static Table table;
    if (!text.empty()) text_ = table.Intern(text);
}

const std::string& InternedString::str() const {
    static const std::string empty;
    return text_ ? *text_ : empty;
}

}  // namespace leaflux
