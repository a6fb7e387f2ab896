// The per-organ CSV (WriteLeafCsv), written as a solver hands the organs' light over
// (OrganSink) in any order and from any thread: the same rows in the same order, receiver
// by receiver. A receiver's rows wait while one before it is missing; the others are
// written at once, so that a solver that reaches the organs about in order (the instanced
// solver opens siblings in their order) holds the light of a few structures, not of the
// whole scene.
#pragma once

#include <map>
#include <mutex>
#include <ostream>
#include <string>
#include <vector>

#include "solver/results/organ_sink.h"
#include "solver/scene/geometry.h"
#include "solver/scene/scene.h"

namespace leaflux {

class LeafCsvStream final : public OrganSink {
  public:
    // Writes the header. `out`, `scene` and `flat` outlive the stream; `flat`'s receivers are
    // the solver's.
    LeafCsvStream(std::ostream& out, const Scene& scene, const FlatScene& flat);

    void Put(std::size_t receiver, std::span<const BandLight> bands) override;
    void Skip(std::size_t receiver) override;

    // After the solve: every receiver put or skipped (CHECK), every row written.
    void Finish();
    // The most receivers whose rows waited at once.
    std::size_t MostWaiting() const { return mostWaiting_; }

  private:
    // Receiver `receiver`'s rows (none if skipped), or they wait; then those waiting behind
    // it. Under mutex_.
    void Arrive(std::size_t receiver, std::string rows);

    std::ostream& out_;
    const Scene& scene_;
    const FlatScene& flat_;
    std::mutex mutex_;
    std::size_t next_ = 0;                        // the first receiver not yet written
    std::map<std::size_t, std::string> waiting_;  // their rows; skipped: none
    std::size_t mostWaiting_ = 0;
};

}  // namespace leaflux
