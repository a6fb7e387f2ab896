#include "solver/results/leaf_csv_stream.h"

#include <algorithm>
#include <sstream>
#include <utility>

#include "solver/results/export.h"
#include "solver/util/check.h"

namespace leaflux {

LeafCsvStream::LeafCsvStream(std::ostream& out, const Scene& scene, const FlatScene& flat)
    : out_(out), scene_(scene), flat_(flat) {
    WriteLeafCsvHeader(out_);
}

void LeafCsvStream::Put(std::size_t receiver, std::span<const BandLight> bands) {
    LEAFLUX_CHECK(receiver < flat_.receivers.size());
    LEAFLUX_CHECK_EQ(bands.size(), scene_.bands.size());
    // Formatted by the thread that solved it, written under the lock.
    std::ostringstream rows;
    WriteLeafRows(rows, scene_, flat_.receivers[receiver], bands, {});
    std::lock_guard lock(mutex_);
    Arrive(receiver, std::move(rows).str());
}

void LeafCsvStream::Skip(std::size_t receiver) {
    std::lock_guard lock(mutex_);
    Arrive(receiver, {});
}

void LeafCsvStream::Arrive(std::size_t receiver, std::string rows) {
    LEAFLUX_CHECK(receiver < flat_.receivers.size());
    LEAFLUX_CHECK(receiver >= next_ && !waiting_.contains(receiver));  // once each
    if (receiver != next_) {
        waiting_.emplace(receiver, std::move(rows));
        mostWaiting_ = std::max(mostWaiting_, waiting_.size());
        return;
    }
    out_ << rows;
    ++next_;
    // Those waiting behind it, while they follow on.
    for (auto at = waiting_.begin(); at != waiting_.end() && at->first == next_;
         at = waiting_.erase(at), ++next_)
        out_ << at->second;
}

void LeafCsvStream::Finish() {
    std::lock_guard lock(mutex_);
    LEAFLUX_CHECK(waiting_.empty());
    LEAFLUX_CHECK_EQ(next_, flat_.receivers.size());
    out_.flush();
}

}  // namespace leaflux
