// Points of the unit square spread more evenly than stratified ones: a rank-1 lattice
// (Korobov), x_i = (i / n, i g / n) modulo 1, with the generator g of largest minimum
// distance on the torus, shifted as a whole by a random vector (Cranley–Patterson), which
// keeps each point uniform and so estimates unbiased.
//
// A shadow edge across a patch is an indicator function of the point: its integral from n
// stratified points (one coordinate stratified, the other random) errs as n^(-3/4) at best,
// from n lattice points as n^(-1) up to a logarithm, both coordinates being resolved by
// every point (Dick & Pillichshammer 2010, ch. 3 and 5).
#pragma once

#include <glm/glm.hpp>

namespace leaflux {

class RankOneLattice {
  public:
    explicit RankOneLattice(int count);
    // The lattice of `count` points, built once per count for the whole process.
    static const RankOneLattice& Of(int count);

    int Count() const { return count_; }
    int Generator() const { return generator_; }

    // Point i of the lattice shifted by `shift` (each in [0, 1)).
    glm::dvec2 Point(int i, const glm::dvec2& shift) const;

  private:
    int count_;
    int generator_;
};

}  // namespace leaflux
