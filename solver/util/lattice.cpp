#include "solver/util/lattice.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>

#include "solver/util/check.h"

namespace leaflux {
namespace {

// The shortest non-zero vector of the lattice with generator g, squared and times n²: the
// lattice is its points' differences, so the smallest distance from the origin to
// another point (i, i g mod n) / n, each coordinate taken the short way round the torus.
std::int64_t ShortestSquared(int count, int g) {
    std::int64_t best = std::numeric_limits<std::int64_t>::max();
    for (int i = 1; i < count; ++i) {
        const std::int64_t a = std::min(i, count - i);
        const std::int64_t r = (static_cast<std::int64_t>(i) * g) % count;
        const std::int64_t b = std::min<std::int64_t>(r, count - r);
        best = std::min(best, a * a + b * b);
    }
    return best;
}

}  // namespace

RankOneLattice::RankOneLattice(int count) : count_(count), generator_(1) {
    LEAFLUX_CHECK(count >= 1);
    // Of the generators prime to n, the one whose points lie farthest apart; the smallest
    // on a tie, so that the lattice is a function of n alone.
    std::int64_t widest = -1;
    for (int g = 1; g < count; ++g) {
        if (std::gcd(g, count) != 1) continue;
        const std::int64_t shortest = ShortestSquared(count, g);
        if (shortest > widest) widest = shortest, generator_ = g;
    }
}

const RankOneLattice& RankOneLattice::Of(int count) {
    static std::mutex mutex;
    static std::map<int, std::unique_ptr<const RankOneLattice>> lattices;
    const std::lock_guard lock(mutex);
    auto& lattice = lattices[count];
    if (!lattice) lattice = std::make_unique<const RankOneLattice>(count);
    return *lattice;
}

glm::dvec2 RankOneLattice::Point(int i, const glm::dvec2& shift) const {
    const double n = count_;
    const double u = i / n + shift.x;
    const double v =
        static_cast<double>((static_cast<std::int64_t>(i) * generator_) % count_) / n + shift.y;
    return {u - std::floor(u), v - std::floor(v)};
}

}  // namespace leaflux
