// Refinement: linking, judging, splitting and judging again (Hanrahan 1991, Smits 1994;
// Soler 2003 §3.1). A link is split (the larger node, or a patch subdivided into four)
// while its estimated error — the power it carries times its geometric error
// ((r_R + r_S)/d)² plus its visibility spread 2√(v(1−v)), v the fraction of its rays that
// pass — exceeds the threshold (Thresholds). Candidate links are judged in parallel chunks
// and the verdicts carried out in order, so the links do not depend on the number of
// threads. A link kept only because its rays agreed takes its transfer from rays of its
// own, so that the choice of links does not bias the light they carry.
//
// The refiner adds links to and splits nodes of the hierarchy it is given; it owns
// nothing. A split hands each new patch its parent's light (Field) and calls the split
// hook, through which the driver hands on whatever else it keeps per node.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "solver/radiosity/estimate.h"
#include "solver/radiosity/links.h"
#include "solver/radiosity/visibility.h"

namespace leaflux {

// Refinement (Refiner::Refine): a task, and the verdict on it.
struct Task {
    enum Kind : std::uint8_t {
        kSource,  // light of directional source s on node r
        kPair,    // light of node s on node r
        kSplit,   // the pair (r, s) must be split (its link failed Rerefine)
        kSelf,    // the exchanges inside cluster r
    };
    Kind kind;
    std::uint32_t r, s;
    // Its part of the refinement it belongs to (Refiner::Refine): a task's parts share
    // its part, and the parts of tasks carried out add up to the fraction done.
    float share = 0.0f;
};

// The error a link may carry (W).
struct Thresholds {
    // ε times the power scale the driver chose (the power the sources bring in).
    double errorW = 0.0;
    // A link into a cluster of organs hands every organ under it the cluster's mean light:
    // one hidden in the cluster gets too much from every such link, an exposed one too
    // little, so on an organ their errors add up where those of links into single patches
    // average out. From surfaces, such links may carry errorW times this; from the suns
    // and sky cones errorW / √(their number), for the errors of its links from all the
    // sources share their sign on each organ under it and add up, where a patch's average
    // out as the root of their number.
    double clusterTolerance = 1.0;
    std::size_t sourceCount = 1;
};

class Refiner {
  public:
    // Called after node n was split, its new children in place.
    using SplitHook = std::function<void(std::uint32_t n)>;

    Refiner(NodeModel& model, Field& field, Links& links, const Estimator& estimator,
            const LinkVisibility& visibility, const std::vector<DirectionalSource>& sources,
            const Thresholds& thresholds, SplitHook onSplit = {})
        : hierarchy_(model.Nodes()),
          model_(model),
          field_(field),
          links_(links),
          estimator_(estimator),
          visibility_(visibility),
          sources_(sources),
          thresholds_(thresholds),
          onSplit_(std::move(onSplit)) {}

    // Called after each chunk of tasks with the fraction of the refinement done (0 to 1).
    using ProgressHook = std::function<void(double done)>;

    // Works through the tasks (and the tasks their splits make). Tasks given without a
    // share take an equal part of the whole.
    void Refine(std::vector<Task> stack);
    void OnProgress(ProgressHook progress) { progress_ = std::move(progress); }
    // Refinement judges a link by the light its sender sends when it is made: a sender lit
    // only by light scattered later (a wall facing away from a lamp, the ceiling of a
    // closed greenhouse) was dark then and linked coarsely. With the radiosities of a
    // solution, every link is judged again and split where its error now exceeds the
    // threshold (the classic refine–solve loop). True when a link was split.
    bool Rerefine();

    // The error a link into node r may carry (W), from a node or from a directional source.
    double Threshold(std::uint32_t r) const {
        return model_.Importance(r) * (model_.Shared(r)
                                           ? thresholds_.errorW * thresholds_.clusterTolerance
                                           : thresholds_.errorW);
    }
    double SourceThreshold(std::uint32_t r) const;
    // The W that links from held instance s bring organs r among its leaves
    // (HeldAroundLinks), as refinement measures channels: such a link hands every part of r the
    // light the held instance sends where r's points are, which varies across r as the depth of its
    // organs behind each point does, so r is split while that light exceeds the threshold. Split
    // down to half the held instance's radius only, the 119k-leaf tree's NIR L2 error was 2.04 % at
    // ε = 1e-4 and the 10,000-leaf tree's 1.80 %; split further so, 1.94 and 1.54 %, each for 3 %
    // more time (interleaved runs); the daemon's 1,000-leaf tree at ε = 3e-3 is solved as it was.
    double HeldAroundLight(std::uint32_t r, std::uint32_t s,
                           const std::vector<NodeLink>& links) const;
    // Organs among a held instance's leaves: split down to this share of its radius always,
    // and to the finest while HeldAroundLight exceeds the threshold.
    static constexpr double kHeldAroundCoarsest = 0.5, kHeldAroundFinest = 0.125;

    std::int64_t Rays() const { return rays_; }

    // A local problem: only the nodes under `root` may be split; every other node is a
    // fixed sender, its light held as it is.
    void HoldFixedOutside(std::uint32_t root) { localRoot_ = root; }

  private:
    struct Verdict {
        enum Kind : std::uint8_t { kNone, kLink, kSplitReceiver, kSplitSender };
        Kind kind = kNone;
        NodeLink link;            // kLink of a pair
        float visibility = 0.0f;  // kLink of a source
        std::int64_t rays = 0;
        std::vector<NodeLink> links;  // kLink of overlapping closed instances, for `link`

        static Verdict Of(Kind kind) {
            Verdict verdict;
            verdict.kind = kind;
            return verdict;
        }
    };

    Verdict Judge(const Task& task) const;
    void Carry(const Task& task, const Verdict& verdict, std::vector<Task>& stack);
    Verdict JudgeSource(std::uint32_t r, std::uint32_t s) const;
    Verdict JudgePair(std::uint32_t r, std::uint32_t s) const;
    // Whether node n may be split here: it can be, and it is not held fixed.
    bool CanSplit(std::uint32_t n) const {
        return model_.CanSplit(n) && (localRoot_ == kNoNode || Within(n));
    }
    bool Within(std::uint32_t n) const {
        for (; n != kNoNode; n = hierarchy_[n].parent) {
            if (n == localRoot_) return true;
        }
        return false;
    }
    // Which of r and s a link between them splits: the larger, or the other when the
    // larger cannot be split but is not a closed instance; none when neither can.
    Verdict::Kind SplitChoice(std::uint32_t r, std::uint32_t s) const;
    // Splits node n, subdividing a patch if it must (CanSplit(n) holds).
    void SplitNode(std::uint32_t n);
    // The link's transfer from its estimate and a visibility v.
    void SetTransfer(NodeLink& link, const Estimate& e, double v) const;
    void Value(std::uint32_t r, NodeLink& link, const Estimate& e, std::int64_t& rays) const;
    // The error a link carries with its sender's light of now and a visibility of this
    // spread (Estimate::Error, from what the link kept of its estimate).
    double LinkError(const NodeLink& link, double spread) const;

    const Hierarchy& hierarchy_;
    NodeModel& model_;
    Field& field_;
    Links& links_;
    const Estimator& estimator_;
    const LinkVisibility& visibility_;
    const std::vector<DirectionalSource>& sources_;
    const Thresholds thresholds_;
    SplitHook onSplit_;
    ProgressHook progress_;
    double done_ = 0.0;  // the shares of the tasks carried out
    std::int64_t rays_ = 0;
    std::uint32_t localRoot_ = kNoNode;
};

}  // namespace leaflux
