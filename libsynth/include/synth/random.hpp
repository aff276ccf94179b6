#pragma once
// Random streams of the synthetic probe: the toolkit's generator family
// (awcc/random.hpp), one stream per consumer (velocity forcing, bubble
// arrivals and positions, voltage noise), seeded from the scene seed and the
// stream's tag, and consumed in an order fixed by the physics, never by chunk
// sizes or threads.

#include <cstdint>

#include "awcc/random.hpp"

namespace synth {

using awcc::Rng;
using awcc::splitmix64;

enum class Stream : std::uint64_t { velocity = 1, bubbles = 2, noise = 3 };

}  // namespace synth
