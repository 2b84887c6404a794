#pragma once
/** Counter-based random numbers shared by the path tracer, the GPU-ray validation and the
 *  techniques' CPU-side seeds: a 64-bit hash and the float made of its top bits. */
#include <cstdint>

namespace gilab {

/** 64-bit finaliser of SplitMix64 (Steele, Lea, Flood 2014; Stafford's "Mix13" constants). */
inline uint64_t mix64(uint64_t x) {
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    x ^= x >> 31;
    return x;
}

/** The uniform float in [0, 1) made of the top 24 bits of a hash. */
inline float toUnitFloat(uint64_t h) {
    return float(uint32_t(h >> 40)) * 0x1p-24f;
}

/** SplitMix64's golden-ratio increment: state += kSplitMixIncrement, then mix64(state). */
inline constexpr uint64_t kSplitMixIncrement = 0x9e3779b97f4a7c15ull;

}  // namespace gilab
