#pragma once
/**
 * Random numbers and sample warps of the reference path tracer.
 *
 * Every random number is a pure function of (seed, pixel, sample index, dimension): a
 * counter-based hash, so a sample is the same whichever thread renders it and whenever it is
 * rendered (docs/reference.md, "Determinism"). By default the numbers are independent uniform
 * variates, which the per-pixel standard errors of the Accumulator assume; the Owen-scrambled
 * Sobol sampler converges faster but makes those standard errors conservative (too large).
 */
#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/util/random.h"  // mix64, toUnitFloat

namespace gilab::ref {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.31830988618379067154f;

constexpr uint32_t reverseBits32(uint32_t x) {
    x = __builtin_bswap32(x);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    return ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
}

/** The hash at the heart of the nested uniform scramble below: its multiplications only carry
 *  lower bits into higher ones, so bit j of the result depends on bits <= j only. */
inline uint32_t laineKarrasPermutation(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}
/**
 * A nested uniform (Owen) scramble of the 32 bits of x, most significant first, keyed by seed:
 * each bit is flipped by a function of the seed and the bits above it only. Burley 2020,
 * "Practical Hash-based Owen Scrambling" (JCGT 9(4)), §3-4: bit-reverse, the Laine–Karras
 * style hash above, reverse back.
 */
inline uint32_t owenScramble(uint32_t x, uint32_t seed) {
    return reverseBits32(laineKarrasPermutation(reverseBits32(x), seed));
}

/** The first two Sobol dimensions as 32-bit fractions: van der Corput, and the dimension of
 *  primitive polynomial x + 1 (direction numbers v_1 = 1/2, v_{j+1} = v_j xor v_j / 2). */
inline uint32_t sobolDimension0(uint32_t i) {
    return reverseBits32(i);
}

namespace detail {
/** Sobol dimension 1 as four byte tables: entry [k][b] is the xor of the direction numbers of
 *  the set bits of b, placed at index bits 8k..8k+7 (one lookup per byte, no branches).
 *  `reversed`: the same with every entry bit-reversed (reversal is linear under xor). */
struct SobolDimension1Tables {
    uint32_t t[4][256];
    constexpr explicit SobolDimension1Tables(bool reversed) : t{} {
        uint32_t v[32] = {};
        v[0] = 1u << 31;
        for (int j = 1; j < 32; ++j)
            v[j] = v[j - 1] ^ (v[j - 1] >> 1);
        for (int k = 0; k < 4; ++k)
            for (uint32_t b = 0; b < 256; ++b) {
                for (int bit = 0; bit < 8; ++bit)
                    if (b & (1u << bit)) t[k][b] ^= v[8 * k + bit];
                if (reversed) t[k][b] = reverseBits32(t[k][b]);
            }
    }
    constexpr uint32_t operator()(uint32_t i) const {
        return t[0][i & 0xffu] ^ t[1][(i >> 8) & 0xffu] ^ t[2][(i >> 16) & 0xffu] ^ t[3][i >> 24];
    }
};
inline constexpr SobolDimension1Tables kSobolDimension1{false};
inline constexpr SobolDimension1Tables kSobolDimension1Reversed{true};
}  // namespace detail

inline uint32_t sobolDimension1(uint32_t i) {
    return detail::kSobolDimension1(i);
}

/** How the sampler makes its numbers (docs/reference.md, "Samplers"). */
enum class SamplerKind { Independent, Sobol };
const char* samplerKindName(SamplerKind k);  // "independent", "sobol"

/**
 * Counter-based sampler of one (seed, pixel, sample). Every number is a pure function of
 * (seed, pixel, sample index, dimension), consumed in a fixed order along the path, so a sample
 * is the same whichever thread renders it and whenever it is rendered.
 *  - Independent: dimension d gives mix64(key ^ (d + 1) * golden),
 *    key = mix64(mix64(mix64(seed) ^ pixel) ^ sample): i.i.d. uniforms.
 *  - Sobol: each get1D / get2D call is one "pad" (Burley 2020 §5): the pixel's samples of that
 *    call form an Owen-scrambled (0, 2)-sequence in base 2 (Sobol dimensions 0 and 1; 1D calls
 *    use dimension 0), with the sample index itself Owen-scrambled per call so pads are
 *    decorrelated. Seeds are hashes of (seed, pixel, call). The samples come in replicates
 *    of 2^replicateLog2: each replicate is its own scrambled sequence (seeds also hash the
 *    replicate's index), so the replicates are independent randomised quasi-Monte Carlo
 *    estimates and their spread gives honest error bars (docs/reference.md, "Samplers").
 */
class Sampler {
public:
    Sampler() = default;
    Sampler(uint64_t seed, uint64_t pixel, uint64_t sampleIndex,
            SamplerKind kind = SamplerKind::Independent, uint32_t replicateLog2 = 32)
        : m_kind(kind) {
        const uint64_t pixelKey = mix64(mix64(seed + 0x632be59bd9b4e019ull) ^ pixel);
        m_key = mix64(pixelKey ^ sampleIndex);
        if (kind == SamplerKind::Sobol) {
            // Replicate r = sampleIndex >> replicateLog2 is the prefix of its own scrambled
            // sequence (at most 2^32 long: an index has 32 bits)
            const uint32_t log2 = replicateLog2 < 32 ? replicateLog2 : 32;
            const uint64_t replicate = sampleIndex >> log2;
            m_sequenceKey = replicate == 0 ? pixelKey : mix64(pixelKey ^ replicate);
            m_reversedIndex = reverseBits32(uint32_t(sampleIndex & ((uint64_t(1) << log2) - 1)));
        }
    }

    float get1D() {
        if (!sobolDraw()) return toUnitFloat(nextHash());
        const uint64_t h = nextPadHash();
        return float(scrambledDimension0(h) >> 8) * 0x1p-24f;
    }
    /** 53-bit uniform in [0, 1), for choices among millions of items (light selection). */
    double get1DDouble() {
        if (!sobolDraw()) return double(nextHash() >> 11) * 0x1p-53;
        const uint64_t h = nextPadHash();
        const uint32_t x = scrambledDimension0(h);
        const uint64_t low = mix64(h) >> 43;  // 21 random low bits below the 32 stratified ones
        return double((uint64_t(x) << 21) | low) * 0x1p-53;
    }
    glm::vec2 get2D() {
        if (!sobolDraw()) {
            const float a = toUnitFloat(nextHash());
            return {a, toUnitFloat(nextHash())};
        }
        // owenScramble(sobolDimension_d(i), seed_d) for the shuffled index i, with the bit
        // reversals that cancel left out (sobolDimension0 is one; see scrambledDimension0)
        const uint64_t h = nextPadHash();
        const uint32_t i = reverseBits32(laineKarrasPermutation(m_reversedIndex, uint32_t(h)));
        const uint64_t h2 = mix64(h);
        const uint32_t x = reverseBits32(laineKarrasPermutation(i, uint32_t(h >> 32)));
        const uint32_t y = reverseBits32(
            laineKarrasPermutation(detail::kSobolDimension1Reversed(i), uint32_t(h2 >> 32)));
        return {float(x >> 8) * 0x1p-24f, float(y >> 8) * 0x1p-24f};
    }
    uint32_t dimension() const { return m_dimension; }

private:
    /** Whether the next draw is a Sobol pad: the first kSobolDraws draws of a path (the camera
     *  ray's pixel position, then the first vertex's light and BSDF draws), where stratification
     *  pays; later draws are i.i.d. hashes, which cost less (measured: docs/reference.md). */
    bool sobolDraw() const { return m_kind == SamplerKind::Sobol && m_dimension < kSobolDraws; }

    static constexpr uint32_t kSobolDraws = 6;
    /** The next draw's hash: of the sample (i.i.d. draws) or of the pixel's sequence (pads). */
    uint64_t nextHash() { return mix64(m_key ^ (uint64_t(++m_dimension) * kGolden)); }
    uint64_t nextPadHash() { return mix64(m_sequenceKey ^ (uint64_t(++m_dimension) * kGolden)); }
    /** owenScramble(sobolDimension0(owenScramble(index, lo(h))), hi(h)): the shuffled index
     *  i = rev(LK(rev(index))), dimension 0 is rev(i), and the scramble reverses it back. */
    uint32_t scrambledDimension0(uint64_t h) const {
        const uint32_t i = reverseBits32(laineKarrasPermutation(m_reversedIndex, uint32_t(h)));
        return reverseBits32(laineKarrasPermutation(i, uint32_t(h >> 32)));
    }

    static constexpr uint64_t kGolden = 0x9e3779b97f4a7c15ull;
    uint64_t m_key = 0;          // of (seed, pixel, sample)
    uint64_t m_sequenceKey = 0;  // of (seed, pixel): every sample of the pixel shares the pads
    uint32_t m_dimension = 0;
    uint32_t m_reversedIndex = 0;  // of the sample's index in its replicate
    SamplerKind m_kind = SamplerKind::Independent;
};

/** Orthonormal basis around a unit z axis (Duff et al. 2017, "Building an Orthonormal Basis,
 *  Revisited"). */
struct Frame {
    glm::vec3 s, t, n;

    static Frame fromZ(const glm::vec3& n) {
        const float sign = std::copysign(1.0f, n.z);
        const float a = -1.0f / (sign + n.z);
        const float b = n.x * n.y * a;
        return {glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x),
                glm::vec3(b, sign + n.y * n.y * a, -n.y), n};
    }
    glm::vec3 toLocal(const glm::vec3& v) const {
        return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)};
    }
    glm::vec3 toWorld(const glm::vec3& v) const { return v.x * s + v.y * t + v.z * n; }
};

/** Shirley & Chiu 1997 concentric map of [0,1)^2 onto the unit disk. */
inline glm::vec2 sampleConcentricDisk(glm::vec2 u) {
    const glm::vec2 o = 2.0f * u - 1.0f;
    if (o.x == 0.0f && o.y == 0.0f) return glm::vec2(0.0f);
    float r, theta;
    if (std::abs(o.x) > std::abs(o.y)) {
        r = o.x;
        theta = 0.25f * kPi * (o.y / o.x);
    } else {
        r = o.y;
        theta = 0.5f * kPi - 0.25f * kPi * (o.x / o.y);
    }
    return r * glm::vec2(std::cos(theta), std::sin(theta));
}

/** Cosine-weighted direction about +z (Malley's method); pdf = cos(theta) / pi. */
inline glm::vec3 sampleCosineHemisphere(glm::vec2 u) {
    const glm::vec2 d = sampleConcentricDisk(u);
    const float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
    return {d.x, d.y, z};
}

/** Uniform direction on the unit sphere; pdf = 1 / (4 pi). */
inline glm::vec3 sampleUniformSphere(glm::vec2 u) {
    const float z = 1.0f - 2.0f * u.x;
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = 2.0f * kPi * u.y;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

/** Uniform barycentrics (b1, b2) on a triangle (pbrt-v3 §13.6.5: sqrt warp); pdf = 1 / area. */
inline glm::vec2 sampleUniformTriangle(glm::vec2 u) {
    const float su = std::sqrt(u.x);
    return {1.0f - su, u.y * su};
}

/** Veach 1997 §9.2.4 power heuristic (beta = 2) for the technique with pdf fPdf against gPdf;
 *  written as 1 / (1 + (g/f)^2) so huge or infinite pdfs stay finite. */
inline float powerHeuristic(float fPdf, float gPdf) {
    if (!(fPdf > 0.0f)) return 0.0f;
    const float r = gPdf / fPdf;
    return 1.0f / (1.0f + r * r);
}

inline bool isFinite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

inline float maxComponent(const glm::vec3& v) {
    return std::max(v.x, std::max(v.y, v.z));
}

}  // namespace gilab::ref
