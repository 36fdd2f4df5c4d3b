// Whether two state vectors hold the same bits: the test of the caches that reuse what was
// computed at a state (joint coordinates, constraint rows) when they see that state again.
#pragma once
#include <cstring>

#include <Eigen/Core>

namespace abd {

// n doubles at a and b bit for bit (memcmp). Eigen's == compares entry by entry with an
// early exit, which does not vectorise (a Panda step made ~60 such tests of 12 to 108
// entries). Bits, not values: −0.0 and 0.0 differ (a cache then computes once more) and a
// NaN equals itself (the cached value came from the same bits).
inline bool same_bits(const double* a, const double* b, Eigen::Index n) {
  return std::memcmp(a, b, sizeof(double) * static_cast<std::size_t>(n)) == 0;
}

// Two vectors of the same size with the same bits.
template <class A, class B>
bool same_bits(const Eigen::DenseBase<A>& a, const Eigen::DenseBase<B>& b) {
  return a.size() == b.size() && same_bits(a.derived().data(), b.derived().data(), a.size());
}

}  // namespace abd
