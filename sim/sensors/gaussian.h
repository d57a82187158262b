#pragma once
// the simulated sensors' noise: N(0, 1) draws from a 64-bit Mersenne
// Twister by Marsaglia and Tsang's ziggurat (Boost.Random's
// normal_distribution): exact (rejection against the density's own tables
// and tails), deterministic for an engine's seed, and about a fifth of the
// cost of libstdc++'s normal_distribution (Marsaglia's polar method, two
// uniforms, a log and a square root per pair), which drew the IMU's twelve
// numbers a sample and the cone sensor's, 7 % of a run on the true state
// with the oracle planner (perf).
#include <boost/random/normal_distribution.hpp>

namespace paddock::sensors {

using Gaussian = boost::random::normal_distribution<double>;

}  // namespace paddock::sensors
