#pragma once
/**
 * C++ mirror of the sampling and paraboloid mathematics in shaders/common/vpl.glsl, for the CPU
 * tests and for host-side checks. Keep the two in step.
 */
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

namespace gilab::vpl {

inline constexpr float kPi = 3.14159265358979323846f;

/** Interleaved subsets of a Hammersley-ordered set (shaders/common/vpl.glsl
 *  vplInterleaveSubset, which explains the rule). */
inline uint32_t interleaveBlock(uint32_t n, uint32_t stride) {
    uint32_t block = 1;
    while (4ull * block * block * stride <= n)
        block *= 2;
    return block;
}
inline uint32_t interleaveFold(uint32_t k, uint32_t stride) {
    if (stride <= 1) return 0;
    uint32_t bits = 0;
    while ((1u << bits) < stride)
        ++bits;
    uint32_t s = 0;
    for (; k != 0; k >>= bits)
        s ^= k & (stride - 1);
    return s;
}
/** Blocks of fewer than 4 points per run (vpl.glsl vplSmallSet): fold or shifted rows. */
inline bool interleaveSmallSet(uint32_t n, uint32_t stride) {
    return interleaveBlock(n, stride) < 4;
}
/** mode: 0 fold (power-of-two strides, else blocks), 1 blocks (small sets: fold for power-of-two
 *  strides, else rows shifted by c), 2 modulo. */
inline uint32_t interleaveSubset(uint32_t k, uint32_t n, uint32_t stride, uint32_t rotation,
                                 uint32_t mode = 0) {
    if (mode == 2) return (k + rotation) % stride;
    const bool small = interleaveSmallSet(n, stride);
    const bool powerOfTwo = stride > 0 && (stride & (stride - 1)) == 0;
    if ((mode == 0 || small) && powerOfTwo)
        return interleaveFold(k, stride) ^ (rotation & (stride - 1));
    if (small) {
        const uint32_t c = stride % 2 == 0 ? 1 : 2;
        return (k % stride + (c * (k / stride)) % stride + rotation) % stride;
    }
    return (k / interleaveBlock(n, stride) + rotation) % stride;
}

/** Base-2 radical inverse (Van der Corput) of k. */
inline float radicalInverse(uint32_t k) {
    k = (k << 16u) | (k >> 16u);
    k = ((k & 0x55555555u) << 1u) | ((k & 0xAAAAAAAAu) >> 1u);
    k = ((k & 0x33333333u) << 2u) | ((k & 0xCCCCCCCCu) >> 2u);
    k = ((k & 0x0F0F0F0Fu) << 4u) | ((k & 0xF0F0F0F0u) >> 4u);
    k = ((k & 0x00FF00FFu) << 8u) | ((k & 0xFF00FF00u) >> 8u);
    return float(double(k) * 2.3283064365386963e-10);
}

/** Aranha et al. Eq. 1: Hammersley point k of n. */
inline glm::vec2 hammersley(uint32_t k, uint32_t n) {
    return {float(k) / float(n), radicalInverse(k)};
}

/** PCG hash (Jarzynski & Olano 2020, "Hash Functions for GPU Rendering", JCGT 9(3)). */
inline uint32_t pcgHash(uint32_t v) {
    const uint32_t s = v * 747796405u + 2891336453u;
    const uint32_t w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (w >> 22u) ^ w;
}

/**
 * The Cranley-Patterson rotation (Cranley & Patterson 1976, "Randomization of number theoretic
 * methods for multiple integration", SIAM J. Numer. Anal. 13(6)) of a technique's `seed`
 * parameter: an offset in [0, 1)^2 added modulo 1 to every point of a fixed 2D set (a toroidal
 * shift: each shifted set is as well distributed as the original, and over random offsets every
 * point is uniform). Seed 0 is no shift, exactly (the images from before the parameter); any
 * other seed hashes to 24-bit fractions (exact in float).
 */
inline glm::vec2 cranleyPattersonShift(uint32_t seed) {
    if (seed == 0) return {0.0f, 0.0f};
    const uint32_t a = pcgHash(seed), b = pcgHash(a ^ 0x9E3779B9u);
    return {float(a >> 8) * 0x1p-24f, float(b >> 8) * 0x1p-24f};
}

/** Point u shifted by `shift` modulo 1 (GLSL fract(u + shift), shaders/common/vpl.glsl). */
inline glm::vec2 toroidalShift(glm::vec2 u, glm::vec2 shift) {
    glm::vec2 v = u + shift;
    return v - glm::floor(v);
}

/** Hammersley point k of n under the Cranley-Patterson rotation `shift` (vpl.glsl
 *  vplHammersleyShifted); shift (0, 0) is hammersley(k, n) exactly. */
inline glm::vec2 hammersley(uint32_t k, uint32_t n, glm::vec2 shift) {
    return toroidalShift(hammersley(k, n), shift);
}

/** Shirley-Chiu concentric square-to-disk map (uniform in area). */
inline glm::vec2 concentricDisk(glm::vec2 u) {
    const glm::vec2 o = 2.0f * u - 1.0f;
    if (o.x == 0.0f && o.y == 0.0f) return {0.0f, 0.0f};
    float r, phi;
    if (std::abs(o.x) > std::abs(o.y)) {
        r = o.x;
        phi = 0.25f * kPi * (o.y / o.x);
    } else {
        r = o.y;
        phi = 0.5f * kPi - 0.25f * kPi * (o.x / o.y);
    }
    return r * glm::vec2(std::cos(phi), std::sin(phi));
}

/** Rows t, b, n of an orthonormal frame around unit n (Duff et al. 2017). */
inline glm::mat3 frame(const glm::vec3& n) {
    const float s = n.z >= 0.0f ? 1.0f : -1.0f;
    const float a = -1.0f / (s + n.z);
    const float b = n.x * n.y * a;
    const glm::vec3 t(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
    const glm::vec3 bt(b, s + n.y * n.y * a, -n.y);
    return glm::transpose(glm::mat3(t, bt, n));
}

/** Paraboloid projection of a unit local direction with d.z >= 0 onto the unit disk. */
inline glm::vec2 paraboloidProject(const glm::vec3& d) {
    return glm::vec2(d.x, d.y) / (1.0f + d.z);
}
/** Its inverse: the unit direction of a disk point. */
inline glm::vec3 paraboloidDirection(const glm::vec2& p) {
    const float r2 = glm::dot(p, p);
    return glm::vec3(2.0f * p.x, 2.0f * p.y, 1.0f - r2) / (1.0f + r2);
}
/** Solid angle per unit disk area at disk point p: 4 / (1 + r^2)^2. */
inline float paraboloidSolidAngleDensity(const glm::vec2& p) {
    const float q = 1.0f + glm::dot(p, p);
    return 4.0f / (q * q);
}

/**
 * Flux weight of a second-bounce VPL sampled uniformly on the unit disk of a cluster's map
 * (docs/vpl.md, "Weighting" of the technique docs): cosine emission of the cluster over the disk
 * density, 4 (1 - r^2) / (1 + r^2)^3 per sample of M; its mean over the disk is 1.
 */
inline float diskSampleWeight(const glm::vec2& p) {
    const float r2 = glm::dot(p, p);
    const float q = 1.0f + r2;
    return 4.0f * (1.0f - r2) / (q * q * q);
}

}  // namespace gilab::vpl
